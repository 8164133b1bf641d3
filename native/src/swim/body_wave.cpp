#include "kodawari/swim/body_wave.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>

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

std::vector<Real> fitted_offsets(const Vec3List& rest, Real body_length, const BodyWave& wave, Real phase) {
  const int n = static_cast<int>(rest.size());
  if (n < 4) {
    const std::vector<Real> s = arc_fractions(rest);
    std::vector<Real> out(s.size());
    for (std::size_t i = 0; i < s.size(); ++i) out[i] = body_length * wave_offset(wave, s[i], phase);
    return out;
  }
  std::vector<Real> t(kFitSamples);
  for (int j = 0; j < kFitSamples; ++j) t[j] = Real(j) / (kFitSamples - 1);
  const std::vector<Real> s = arc_fraction_at(ffd::CubicBSpline(rest), t);
  Eigen::MatrixXd basis = Eigen::MatrixXd::Zero(kFitSamples, n);
  Eigen::VectorXd values(kFitSamples);
  for (int j = 0; j < kFitSamples; ++j) {
    const ffd::CubicBasis b = ffd::cubic_basis(n, t[j]);
    for (int k = 0; k < 4; ++k) {
      if (b.first + k < n) basis(j, b.first + k) += b.value[k];
    }
    values[j] = body_length * wave_offset(wave, s[j], phase);
  }
  // The clamped curve starts exactly at its first point: it takes the wave there (a
  // pinned snout stays pinned); the others are fitted by least squares so the B-spline
  // curve (not its control polygon) follows the wave, the tail tip held closely.
  std::vector<Real> out(static_cast<std::size_t>(n));
  out.front() = values[0];
  Eigen::VectorXd rhs = values - basis.col(0) * out.front();
  Eigen::MatrixXd fit = basis.rightCols(n - 1);
  // The tail tip counts twice: its amplitude is the setting (within ~1%).
  constexpr Real kTipWeight = 2;
  fit.row(kFitSamples - 1) *= kTipWeight;
  rhs[kFitSamples - 1] *= kTipWeight;
  const Eigen::VectorXd rest_points = fit.colPivHouseholderQr().solve(rhs);
  for (int i = 1; i < n; ++i) out[static_cast<std::size_t>(i)] = rest_points[i - 1];
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
  const Real rest_curve = ffd::curve_length(ffd::CubicBSpline(rest));
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
