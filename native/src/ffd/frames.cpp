#include "kodawari/ffd/frames.hpp"

#include <cmath>
#include <stdexcept>

namespace kodawari::ffd {

Vec3 default_start_normal(const Vec3& tangent) {
  int axis = 0;
  for (int k = 1; k < 3; ++k) {
    if (std::abs(tangent[k]) < std::abs(tangent[axis])) axis = k;
  }
  const Vec3 world = Vec3::Unit(axis);
  return (world - world.dot(tangent) * tangent).normalized();
}

Vec3 start_normal_from_up(const Vec3& up, const Vec3& tangent) {
  const Vec3 perpendicular = up - up.dot(tangent) * tangent;
  const Real norm = perpendicular.norm();
  if (!(norm > Real(1e-6) * up.norm())) {
    throw std::invalid_argument("up must not be zero or parallel to the curve's start tangent");
  }
  return perpendicular / norm;
}

Vec3 carry_normal(const Vec3& normal, const Vec3& from, const Vec3& to) {
  const Vec3 axis = from.cross(to);
  const Real sine = axis.norm();
  const Real cosine = from.dot(to);
  Vec3 carried;
  if (sine < Real(1e-12)) {
    // Same tangent: nothing to do. Opposite tangent: a half turn about `normal`
    // itself maps from onto to and leaves `normal` where it is.
    carried = normal;
  } else {
    carried = Eigen::AngleAxis<Real>(std::atan2(sine, cosine), axis / sine) * normal;
  }
  // Remove rounding drift so the start frame is exactly orthonormal.
  return (carried - carried.dot(to) * to).normalized();
}

void rotation_minimising_frames(const CurveSamples& samples, const Vec3& start_normal, FrameList& frames) {
  const std::size_t count = samples.origin.size();
  frames.resize(count);
  // Pass 1, independent per step: the two reflection planes. v1 is the chord
  // x_{i-1} -> x_i; v2 maps the tangent reflected in v1 onto t_i. Each plane
  // is stored as (normal, 2 / |normal|^2), zero when the reflection is void.
  for (std::size_t i = 1; i < count; ++i) {
    const Vec3 v1 = samples.origin[i] - samples.origin[i - 1];
    const Real c1 = v1.dot(v1);
    const Real k1 = c1 > 0 ? 2 / c1 : Real(0);
    const Vec3& t_prev = samples.tangent[i - 1];
    const Vec3 v2 = samples.tangent[i] - (t_prev - k1 * v1.dot(t_prev) * v1);
    const Real c2 = v2.dot(v2);
    // Park the planes in the frames' e1/e3 slots until pass 3 overwrites them.
    frames[i].e1 = v1 * std::sqrt(k1);
    frames[i].e3 = v2 * (c2 > 0 ? std::sqrt(2 / c2) : Real(0));
  }
  // Pass 2, the only sequential part: r_i = H2 H1 r_{i-1}, two reflections
  // r <- r - (a . r) a with a = v sqrt(2 / |v|^2). Reflections are orthogonal,
  // so r stays unit up to rounding (renormalised on output, not fed back).
  Vec3 r = start_normal;
  frames[0].e2 = r;
  for (std::size_t i = 1; i < count; ++i) {
    const Vec3& a1 = frames[i].e1;
    const Vec3& a2 = frames[i].e3;
    r -= a1.dot(r) * a1;
    r -= a2.dot(r) * a2;
    frames[i].e2 = r;
  }
  // Pass 3, independent: exact orthonormal frames, then the twist roll.
  for (std::size_t i = 0; i < count; ++i) {
    Frame& f = frames[i];
    const Vec3& tangent = samples.tangent[i];
    const Vec3 normal = (f.e2 - f.e2.dot(tangent) * tangent).normalized();
    const Vec3 binormal = tangent.cross(normal);
    f.origin = samples.origin[i];
    f.e1 = tangent;
    if (samples.roll.empty()) {
      f.e2 = normal;
      f.e3 = binormal;
    } else {
      const Real c = std::cos(samples.roll[i]), sn = std::sin(samples.roll[i]);
      f.e2 = c * normal + sn * binormal;
      f.e3 = c * binormal - sn * normal;
    }
  }
}

}  // namespace kodawari::ffd
