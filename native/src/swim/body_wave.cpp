#include "kodawari/swim/body_wave.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <complex>
#include <optional>

#include "kodawari/ffd/bspline.hpp"
#include "kodawari/ffd/lengths.hpp"

namespace kodawari::swim {

Real wave_envelope(const BodyWave& wave, Real s) {
  // Grows from amplitude_head (snout) to amplitude (tail tip) after envelope_start.
  const Real start = std::clamp(wave.envelope_start, Real(0), Real(0.999));
  const Real x = std::clamp((s - start) / (Real(1) - start), Real(0), Real(1));
  const Real growth = std::pow(x, std::max(wave.envelope_power, Real(1e-3)));
  return wave.amplitude_head + (wave.amplitude - wave.amplitude_head) * growth;
}

Real wave_offset(const BodyWave& wave, Real s, Real phase) {
  const Real k = Real(2) * kPi / std::max(wave.wavelength, Real(1e-6));
  return wave_envelope(wave, s) * std::sin(phase + wave.phase_offset - k * s);
}

std::vector<Real> arc_fractions(const Vec3List& points) {
  std::vector<Real> s(points.size(), Real(0));
  for (std::size_t i = 1; i < points.size(); ++i) s[i] = s[i - 1] + (points[i] - points[i - 1]).norm();
  const Real total = s.empty() ? Real(0) : s.back();
  if (total > Real(0)) {
    for (Real& v : s) v /= total;
  }
  return s;
}

namespace {

constexpr int kFitSamples = 96;  // curve samples the control offsets are fitted to

// Arc-length fraction of the rest curve at parameters t (dense samples, interpolated).
std::vector<Real> arc_fraction_at(const ffd::CubicBSpline& curve, const std::vector<Real>& t) {
  constexpr int kSamples = 256;
  std::vector<Real> arc(kSamples + 1, Real(0));
  Vec3 previous = curve.point(0);
  for (int k = 1; k <= kSamples; ++k) {
    const Vec3 here = curve.point(Real(k) / kSamples);
    arc[k] = arc[k - 1] + (here - previous).norm();
    previous = here;
  }
  std::vector<Real> out(t.size());
  for (std::size_t j = 0; j < t.size(); ++j) {
    const Real x = std::clamp(t[j], Real(0), Real(1)) * kSamples;
    const int k = std::clamp(static_cast<int>(x), 0, kSamples - 1);
    const Real a = arc[k] + (x - k) * (arc[k + 1] - arc[k]);
    out[j] = arc.back() > 0 ? a / arc.back() : t[j];
  }
  return out;
}

}  // namespace

namespace {

// Wavelength (in arc fraction) of the complex wave `c` along `s`: the phase slope of the
// fundamental fitted where its amplitude is at least a third of its largest (the part of
// the body where the wave is seen). 0 when there is no such stretch.
Real seen_wavelength(const Eigen::VectorXcd& c, const std::vector<Real>& s) {
  const Real peak = c.cwiseAbs().maxCoeff();
  if (!(peak > 0)) return 0;
  Real sum_s = 0, sum_p = 0, sum_ss = 0, sum_sp = 0, unwrapped = 0, previous = 0;
  int used = 0;
  bool first = true;
  for (Eigen::Index j = 0; j < c.size(); ++j) {
    if (std::abs(c[j]) <= peak / 3) continue;
    const Real angle = std::arg(c[j]);
    if (first) {
      unwrapped = angle;
      first = false;
    } else {
      Real step = angle - previous;
      step -= 2 * kPi * std::round(step / (2 * kPi));
      unwrapped += step;
    }
    previous = angle;
    const Real x = s[static_cast<std::size_t>(j)];
    sum_s += x;
    sum_p += unwrapped;
    sum_ss += x * x;
    sum_sp += x * unwrapped;
    ++used;
  }
  const Real spread = used * sum_ss - sum_s * sum_s;
  if (used < 3 || !(spread > 0)) return 0;
  const Real slope = (used * sum_sp - sum_s * sum_p) / spread;
  return std::abs(slope) > 0 ? 2 * kPi / std::abs(slope) : 0;
}

}  // namespace

namespace {

// What a body wave on one rest axis does not owe to its phase: the complex fit of the
// control offsets per unit body length (docs/algorithms.md §2.1) and the rest curve's arc
// length (§2.3). A swimming fish asks for the same rest axis and settings every frame.
struct WaveShape {
  Eigen::VectorXcd fit;
  Real rest_curve = 0;
};

WaveShape compute_wave_shape(const Vec3List& rest, const BodyWave& wave) {
  const int n = static_cast<int>(rest.size());
  std::vector<Real> t(kFitSamples);
  for (int j = 0; j < kFitSamples; ++j) t[j] = Real(j) / (kFitSamples - 1);
  const std::vector<Real> s = arc_fraction_at(ffd::CubicBSpline(rest), t);
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(kFitSamples, n);
  for (int j = 0; j < kFitSamples; ++j) {
    const ffd::CubicBasis b = ffd::cubic_basis(n, t[j]);
    for (int k = 0; k < 4; ++k) {
      if (b.first + k < n) basis(j, b.first + k) += b.value[k];
    }
  }
  // The wave is linear in its complex form w(s) = A(s)·e^(−iks): the offsets at phase φ are
  // Im(e^(i(φ+φ0))·x) for the complex fit x of w (docs/algorithms.md §2.1). The clamped curve
  // starts exactly at its first point: it takes the wave there (a pinned snout stays
  // pinned); the others are fitted by least squares so the B-spline curve (not its control
  // polygon) follows the wave, the tail tip held closely (counted twice: its amplitude is
  // the setting within ~1%).
  constexpr Real kTipWeight = 2;
  Eigen::MatrixXd fit = basis.rightCols(n - 1);
  fit.row(kFitSamples - 1) *= kTipWeight;
  const Eigen::ColPivHouseholderQR<Eigen::MatrixXd> solver(fit);
  auto complex_fit = [&](Real k) {
    Eigen::VectorXd re(kFitSamples), im(kFitSamples);
    for (int j = 0; j < kFitSamples; ++j) {
      const Real a = wave_envelope(wave, s[static_cast<std::size_t>(j)]);
      re[j] = a * std::cos(k * s[static_cast<std::size_t>(j)]);
      im[j] = -a * std::sin(k * s[static_cast<std::size_t>(j)]);
    }
    Eigen::VectorXcd x(n);
    x[0] = std::complex<Real>(re[0], im[0]);
    Eigen::VectorXd rhs_re = re - basis.col(0) * re[0];
    Eigen::VectorXd rhs_im = im - basis.col(0) * im[0];
    rhs_re[kFitSamples - 1] *= kTipWeight;
    rhs_im[kFitSamples - 1] *= kTipWeight;
    const Eigen::VectorXd x_re = solver.solve(rhs_re);
    const Eigen::VectorXd x_im = solver.solve(rhs_im);
    for (int i = 1; i < n; ++i) x[i] = std::complex<Real>(x_re[i - 1], x_im[i - 1]);
    return x;
  };
  // A spline of few points cannot follow a fast-growing envelope exactly, and the wave it
  // does carry comes out longer or shorter than asked (thunniform: +34% at 6 points, −6% at
  // 9). The wave number fitted is corrected until the curve's own wave — where it is seen —
  // has the set wavelength (a few secant-like steps, bounded).
  const Real wanted = std::max(wave.wavelength, Real(1e-6));
  Real k = 2 * kPi / wanted;
  Eigen::VectorXcd x = complex_fit(k);
  constexpr int kCalibrationSteps = 6;
  for (int step = 0; step < kCalibrationSteps; ++step) {
    const Real seen = seen_wavelength(basis * x, s);  // real basis times complex fit, no copy
    if (!(seen > 0) || std::abs(seen / wanted - 1) < 1e-3) break;
    k *= std::clamp(seen / wanted, Real(0.5), Real(2));
    x = complex_fit(k);
  }
  return WaveShape{x, ffd::curve_length(ffd::CubicBSpline(rest))};
}

// The last few shapes asked for on this thread, found by their exact inputs (a path bends
// the rest axis anew every frame: those miss and cost what they did before). The result
// is bit for bit the one computed afresh.
WaveShape wave_shape(const Vec3List& rest, const BodyWave& wave) {
  struct Entry {
    Vec3List rest;
    std::array<Real, 5> settings;
    WaveShape shape;
  };
  constexpr std::size_t kEntries = 8;
  thread_local std::array<std::optional<Entry>, kEntries> memo;
  thread_local std::size_t next = 0;
  const std::array<Real, 5> settings = {wave.wavelength, wave.amplitude, wave.amplitude_head, wave.envelope_start,
                                        wave.envelope_power};
  for (const auto& entry : memo) {
    if (entry && entry->settings == settings && entry->rest == rest) return entry->shape;
  }
  WaveShape shape = compute_wave_shape(rest, wave);
  memo[next] = Entry{rest, settings, shape};
  next = (next + 1) % kEntries;
  return shape;
}

}  // namespace

std::vector<Real> fitted_offsets(const Vec3List& rest, Real body_length, const BodyWave& wave, Real phase) {
  const int n = static_cast<int>(rest.size());
  if (n < 4) {
    const std::vector<Real> s = arc_fractions(rest);
    std::vector<Real> out(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) out[i] = body_length * wave_offset(wave, s[i], phase);
    return out;
  }
  const Eigen::VectorXcd x = wave_shape(rest, wave).fit;
  const std::complex<Real> turn = std::polar(body_length, phase + wave.phase_offset);
  std::vector<Real> out(static_cast<std::size_t>(n));
  for (int i = 0; i < n; ++i) out[static_cast<std::size_t>(i)] = (turn * x[i]).imag();
  return out;
}

Vec3List body_axis(const Vec3List& rest, const Vec3& bend_direction, Real body_length, const BodyWave& wave,
                   Real phase) {
  const std::size_t n = rest.size();
  // The control offsets are fitted (least squares over the whole curve) so the B-SPLINE
  // CURVE follows the wave. Offsetting the control points by the wave itself lets the
  // approximating spline blur the phase where the envelope grows fast: the wave came out
  // up to 47% long (thunniform, 8 points; docs/algorithms.md §2.1).
  const std::vector<Real> wanted = fitted_offsets(rest, body_length, wave, phase);

  Vec3List targets(n);
  for (std::size_t i = 0; i < n; ++i) targets[i] = rest[i] + wanted[i] * bend_direction;
  if (!wave.preserve_length || n < 2) return targets;

  const std::vector<Real> rest_lengths = ffd::segment_lengths(rest);

  // The distance-keeping walk shortens the sideways offsets a little (each point is
  // pulled toward its neighbour); a few fixed-point passes aim the targets further
  // out so the achieved offsets follow the wave, which keeps the tail amplitude true.
  auto keep_lengths = [&](const std::vector<Real>& lengths) {
    std::vector<Real> aim(wanted);
    Vec3List placed;
    constexpr int kPasses = 8;
    for (int pass = 0; pass < kPasses; ++pass) {
      for (std::size_t i = 0; i < n; ++i) targets[i] = rest[i] + aim[i] * bend_direction;
      placed = ffd::preserve_lengths_from_head(targets, lengths);
      if (pass + 1 == kPasses) break;
      for (std::size_t i = 0; i < n; ++i) {
        const Real achieved = (placed[i] - rest[i]).dot(bend_direction);
        // Bounded so an unreachable wave (offset steps longer than a segment) cannot run away.
        aim[i] = std::clamp(aim[i] + (wanted[i] - achieved), -2 * std::abs(wanted[i]) - 1e-9,
                            2 * std::abs(wanted[i]) + 1e-9);
      }
    }
    return placed;
  };
  Vec3List placed = keep_lengths(rest_lengths);
  if (n < 4) return placed;

  // The body follows the smooth B-spline, which cuts the bent polygon's corners and
  // so comes out shorter than at rest; scale the kept distances until the curve's
  // own arc length is the rest one again (converges in a few passes).
  const Real rest_curve = wave_shape(rest, wave).rest_curve;
  Real scale = 1.0;
  for (int pass = 0; pass < 4; ++pass) {
    const Real now = ffd::curve_length(ffd::CubicBSpline(placed));
    if (!(now > 0) || std::abs(now - rest_curve) <= 1e-9 * rest_curve) break;
    scale *= rest_curve / now;
    std::vector<Real> lengths(rest_lengths);
    for (Real& l : lengths) l *= scale;
    placed = keep_lengths(lengths);
  }
  return placed;
}

std::vector<Real> accumulate_phase(const std::vector<Real>& frequencies, Real dt, Real phase0) {
  std::vector<Real> phase(frequencies.size());
  if (phase.empty()) return phase;
  phase[0] = phase0;
  for (std::size_t k = 1; k < phase.size(); ++k) {
    phase[k] = phase[k - 1] + kPi * (frequencies[k - 1] + frequencies[k]) * dt;
  }
  return phase;
}

}  // namespace kodawari::swim
