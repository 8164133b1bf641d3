#include "kodawari/swim/fin_motion.hpp"

#include <algorithm>
#include <cmath>

#include "kodawari/swim/body_wave.hpp"

namespace kodawari::swim {

Mat3 axis_rotation(const Vec3& unit_axis, Real angle) {
  return Eigen::AngleAxis<Real>(angle, unit_axis).toRotationMatrix();
}

namespace {

// Unit vector of a × b, or `fallback` when a and b are (nearly) parallel.
Vec3 cross_or(const Vec3& a, const Vec3& b, const Vec3& fallback) {
  const Vec3 c = a.cross(b);
  const Real norm = c.norm();
  return norm > Real(0.3) ? Vec3(c / norm) : fallback.normalized();
}

}  // namespace

Vec3 flap_stroke_direction(const Vec3& fin_axis, const RootFrame& frame) {
  const Vec3 axis = fin_axis.normalized();
  const Vec3 k = cross_or(axis, frame.tangent, frame.up);
  return k.cross(axis).normalized();
}

FinPose fin_axis(const Vec3List& rest, const RootFrame& frame, const FinWave& wave, Real phase) {
  FinPose pose{rest, std::vector<Real>(rest.size(), Real(0))};
  const std::size_t m = rest.size();
  if (m < 2) return pose;
  const Vec3 span = rest.back() - rest.front();
  const Real length = span.norm();
  if (length <= Real(0)) return pose;
  const Vec3 axis = span / length;

  if (wave.motion == FinMotion::Undulate) {
    // A wave along the fin base (dorsal/anal fins of balistiform swimmers).
    const std::vector<Real> s = arc_fractions(rest);
    const Real k = Real(2) * kPi / std::max(wave.wavelength, Real(1e-6));
    for (std::size_t i = 0; i < m; ++i) {
      pose.points[i] = rest[i] + wave.amplitude * length * std::sin(phase - k * s[i]) * frame.side;
    }
    return pose;
  }

  // The outer points turn about the last fixed one (the hinge); the fixed points
  // clustered at the root keep the fin attached (docs/algorithms.md §2.4).
  const std::size_t fixed = std::clamp<std::size_t>(std::size_t(std::max(wave.fixed_count, 1)), 1, m - 1);
  const Vec3 hinge = rest[fixed - 1];
  Mat3 rotation = Mat3::Identity();
  Real roll = 0;
  switch (wave.motion) {
    case FinMotion::Flap: {
      // Tip moves fore/aft; a fin lying along the body (caudal) moves sideways.
      const Vec3 k = cross_or(axis, frame.tangent, frame.up);
      rotation = axis_rotation(k, wave.amplitude * std::sin(phase));
      // Feathering (docs/algorithms.md §2.4): blade across the motion on the power stroke (tip moving
      // tailward, cos φ > 0), nearly edge-on on the recovery. The roll sits on whichever
      // stroke the modelled blade does not already match.
      const Real toward = wave.feather_on_power ? Real(1) + std::cos(phase) : Real(1) - std::cos(phase);
      roll = wave.feathering * Real(0.5) * toward;
      break;
    }
    case FinMotion::UpDown: {
      const Real along = std::abs(axis.dot(frame.tangent));
      const Vec3 k = along > Real(0.95) ? frame.side.normalized() : frame.tangent.normalized();
      rotation = axis_rotation(k, wave.amplitude * std::sin(phase));
      break;
    }
    case FinMotion::Twist:
      roll = wave.amplitude * std::sin(phase);
      break;
    case FinMotion::Undulate:
      break;
  }
  for (std::size_t i = fixed; i < m; ++i) {
    pose.points[i] = hinge + rotation * (rest[i] - hinge);
    pose.twist[i] = roll;
  }
  return pose;
}

}  // namespace kodawari::swim
