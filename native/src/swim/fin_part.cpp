#include "kodawari/swim/fin_part.hpp"

#include <Eigen/Dense>

#include <algorithm>
#include <array>
#include <cmath>
#include <utility>
#include <stdexcept>

#include "kodawari/parallel.hpp"

namespace kodawari::swim {

namespace {

constexpr Real kMaxShear = 0.35;
// A rowing fin's feathering (docs/algorithms.md §2.4): with the swing, under 1.5× at 0.6 rad.
constexpr Real kMaxRowingShear = 0.85;
// An undulation's steepest slope (wave along the base and fade across the fin together).
constexpr Real kMaxUndulationSlope = 0.8;
constexpr int kFadeSamples = 64;

Real smoothstep(Real x) {
  x = std::clamp(x, Real(0), Real(1));
  return x * x * (Real(3) - Real(2) * x);
}

// The swing integrated along the fin (docs/algorithms.md §2.4): a fin line at reach r
// bends so that its direction at ρ is turned by angle·w(ρ); its point at r moves by
// ∫0^r (R(angle·w(ρ)) − I)·outward dρ = S(r)·(a × n) + C(r)·(a × (a × n)). Every
// line keeps its length, so the fade adds no stretch of its own (a per-vertex lever
// r·(R(angle·w(r)) − I)·n stretches lines by √(1 + (r·angle·w'(r))²) and then some).
struct SwingIntegral {
  Real step = 0, sin_full = 0, cos_full = 0;
  std::array<Real, kFadeSamples + 1> s{}, c{};

  SwingIntegral(Real angle, Real fade) {
    sin_full = std::sin(angle);
    cos_full = Real(1) - std::cos(angle);
    if (fade <= 0) return;
    step = fade / kFadeSamples;
    Real prev_s = 0, prev_c = 0;
    for (int k = 0; k <= kFadeSamples; ++k) {
      const Real a = angle * smoothstep(Real(k) / kFadeSamples);
      const Real ss = std::sin(a), cc = Real(1) - std::cos(a);
      if (k > 0) {
        s[k] = s[k - 1] + Real(0.5) * step * (prev_s + ss);
        c[k] = c[k - 1] + Real(0.5) * step * (prev_c + cc);
      }
      prev_s = ss;
      prev_c = cc;
    }
  }

  // (S(r), C(r)).
  std::pair<Real, Real> at(Real r) const {
    if (step <= 0) return {r * sin_full, r * cos_full};
    const Real x = r / step;
    if (x >= kFadeSamples) {
      const Real extra = r - step * kFadeSamples;
      return {s[kFadeSamples] + extra * sin_full, c[kFadeSamples] + extra * cos_full};
    }
    const int k = static_cast<int>(std::max(x, Real(0)));
    const Real t = std::max(x, Real(0)) - k;
    return {s[k] + t * (s[k + 1] - s[k]), c[k] + t * (c[k + 1] - c[k])};
  }
};

Vec3 unit_cross_or(const Vec3& a, const Vec3& b, const Vec3& fallback) {
  const Vec3 c = a.cross(b);
  const Real norm = c.norm();
  return norm > Real(0.3) ? Vec3(c / norm) : fallback.normalized();
}

}  // namespace

Vec3 swing_hinge(FinMotion motion, const Vec3& outward, const RootFrame& frame) {
  const Vec3 n = outward.normalized();
  switch (motion) {
    case FinMotion::Flap:
      return unit_cross_or(n, frame.tangent, frame.up);
    case FinMotion::UpDown:
      return std::abs(n.dot(frame.tangent.normalized())) > Real(0.95) ? Vec3(frame.side.normalized())
                                                                     : Vec3(frame.tangent.normalized());
    case FinMotion::Twist:
    case FinMotion::Undulate:
      break;
  }
  return Vec3::Zero();
}

Vec3 swing_direction(FinMotion motion, const Vec3& outward, const RootFrame& frame) {
  const Vec3 s = swing_hinge(motion, outward, frame).cross(outward.normalized());
  const Real norm = s.norm();
  return norm > Real(1e-9) ? Vec3(s / norm) : Vec3::Zero();
}

FinPartBinding::FinPartBinding(const Vec3List& points, const std::vector<Real>& reach,
                               const std::vector<Real>& weight_in, const FinPartRest& rest, Real fade)
    : reach_(reach), weight_(weight_in), group_(weight_in), rest_(rest), fade_(std::max(fade, Real(0))) {
  const std::size_t m = points.size();
  if (reach.size() != m || weight_in.size() != m) throw std::invalid_argument("reach and weight need one value per point");
  if (fade_ > 0) {
    for (std::size_t i = 0; i < m; ++i) weight_[i] = group_[i] * smoothstep(reach[i] / fade_);
  }
  const std::vector<Real>& weight = weight_;
  if (!(rest_.outward.norm() > 0)) throw std::invalid_argument("the fin's outward direction is zero");
  rest_.outward.normalize();
  across_.resize(m);
  height_.resize(m);
  along_.resize(m);
  const Real base = std::max(rest_.base_length, Real(1e-9));
  // The fade's steepest slope: d(weight)/d(reach) between vertices sorted by reach.
  std::vector<std::size_t> order(m);
  for (std::size_t i = 0; i < m; ++i) order[i] = i;
  std::sort(order.begin(), order.end(), [&](std::size_t a, std::size_t b) { return reach[a] < reach[b]; });
  Real roll_lever = 0, slope = 0;
  for (std::size_t i = 0; i < m; ++i) {
    const Vec3 d = points[i] - rest_.root;
    height_[i] = d.dot(rest_.outward);
    across_[i] = d - height_[i] * rest_.outward;
    along_[i] = (points[i].dot(rest_.frame.tangent) - rest_.base_front) / base;
  }
  // Slope over a window of neighbours in reach (robust to duplicate reaches).
  const std::size_t window = std::max<std::size_t>(1, m / 50);
  for (std::size_t k = 0; k + window < m; ++k) {
    const std::size_t a = order[k], b = order[k + window];
    const Real dr = reach[b] - reach[a];
    if (dr <= 0) continue;
    const Real g = std::abs(weight[b] - weight[a]) / dr;
    slope = std::max(slope, g);
    roll_lever = std::max(roll_lever, g * std::max(across_[a].norm(), across_[b].norm()));
  }
  max_roll_ = roll_lever > 0 ? kMaxShear / roll_lever : kPi;
  max_feather_ = roll_lever > 0 ? kMaxRowingShear / roll_lever : kPi;
  max_undulation_ = slope > 0 ? kMaxShear / slope : rest_.height;
}

void FinPartBinding::displace(const FinWave& wave, Real phase, const Mat3& body_rotation, float* out) const {
  const Vec3& outward = rest_.outward;
  const RootFrame& f = rest_.frame;
  Vec3 hinge_axis = Vec3::Zero();
  Real angle = 0, roll = 0, undulation = 0;
  switch (wave.motion) {
    case FinMotion::Flap: {
      hinge_axis = swing_hinge(wave.motion, outward, f);
      angle = wave.amplitude * std::sin(phase);
      const Real toward = wave.feather_on_power ? Real(1) + std::cos(phase) : Real(1) - std::cos(phase);
      // Not held here: a rowing blade must turn edge-on (the caller holds feathering on
      // fins that do not row, docs/algorithms.md §2.4).
      roll = wave.feathering * Real(0.5) * toward;
      break;
    }
    case FinMotion::UpDown:
      hinge_axis = swing_hinge(wave.motion, outward, f);
      angle = wave.amplitude * std::sin(phase);
      break;
    case FinMotion::Twist:
      // A twist of a long-based fin swings its ends; held where the fade would shear past 0.5.
      roll = std::clamp(wave.amplitude * std::sin(phase), -max_roll_, max_roll_);
      break;
    case FinMotion::Undulate: {
      // Amplitude is a fraction of the fin's height; the wave may not tilt the fin's
      // surface past 45° (slope 1), which would fold it.
      const Real k = Real(2) * kPi / (std::max(wave.wavelength, Real(1e-6)) * std::max(rest_.base_length, Real(1e-9)));
      // With the fade's own slope across the fin, the surface may tilt by at most
      // kMaxUndulationSlope (an edge then stretches by at most √(1 + 0.8²) ≈ 1.28).
      const Real fade_slope = max_undulation_ > 0 ? kMaxShear / max_undulation_ : Real(0);
      undulation = std::min(wave.amplitude * rest_.height,
                            kMaxUndulationSlope / std::sqrt(k * k + fade_slope * fade_slope));
      break;
    }
  }
  const Real k_wave = Real(2) * kPi / std::max(wave.wavelength, Real(1e-6));
  const SwingIntegral integral(angle, fade_);
  const Vec3 bend_1 = hinge_axis.cross(outward), bend_2 = hinge_axis.cross(bend_1);
  parallel_for(reach_.size(), 0, 8192, [&](std::size_t begin, std::size_t end) {
  for (std::size_t i = begin; i < end; ++i) {
    const Real w = weight_[i];
    Vec3 d = Vec3::Zero();
    if (w > 0) {
      if (wave.motion == FinMotion::Undulate) {
        d = w * undulation * std::sin(phase - k_wave * along_[i]) * f.side;
      } else {
        // Swing about the vertex's own root point, bent along its line across the fin.
        const Mat3 swing = angle != 0 ? axis_rotation(hinge_axis, w * angle) : Mat3::Identity();
        const Mat3 twist = roll != 0 ? axis_rotation(outward, w * roll) : Mat3::Identity();
        if (angle != 0) {
          if (fade_ > 0) {
            const auto [s_r, c_r] = integral.at(reach_[i]);
            d = group_[i] * (s_r * bend_1 + c_r * bend_2);
          } else {
            d = (swing - Mat3::Identity()) * (reach_[i] * outward);
          }
        }
        d += swing * (twist - Mat3::Identity()) * across_[i];
      }
      d = body_rotation * d;
    }
    for (int c = 0; c < 3; ++c) out[3 * i + c] = static_cast<float>(d[c]);
  }
  });
}

Mat3 probe_rotation(const Vec3List& rest, const Vec3List& now) {
  if (rest.size() != 4 || now.size() != 4) throw std::invalid_argument("probe_rotation needs 4 points each");
  Mat3 before, moved;
  for (int c = 0; c < 3; ++c) {
    before.col(c) = rest[c + 1] - rest[0];
    moved.col(c) = now[c + 1] - now[0];
  }
  // The rotation part of the arms' linear map. Arms that span no volume (collapsed or
  // collinear probes) have no inverse: then the best rotation of the arms onto each other
  // (Kabsch: the cross-covariance moved * before^T), which is the identity for zero arms.
  const double scale = before.norm();
  const bool invertible = scale > 0 && std::abs(before.determinant()) > 1e-9 * scale * scale * scale;
  Mat3 map = invertible ? Mat3(moved * before.inverse()) : Mat3(moved * before.transpose());
  if (!map.allFinite()) map = Mat3::Identity();
  Eigen::JacobiSVD<Mat3> svd(map, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Mat3 u = svd.matrixU();
  Mat3 r = u * svd.matrixV().transpose();
  if (r.determinant() < 0) {
    u.col(2) *= -1;
    r = u * svd.matrixV().transpose();
  }
  return r;
}

}  // namespace kodawari::swim
