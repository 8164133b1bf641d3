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
  Vec3 r = start_normal;
  for (std::size_t i = 0; i < count; ++i) {
    const Vec3& x = samples.origin[i];
    const Vec3& tangent = samples.tangent[i];
    if (i > 0) {
      // Reflect (r, t) in the bisector plane of x_prev -> x, then in the plane
      // that maps the reflected tangent onto the new tangent.
      const Vec3 v1 = x - samples.origin[i - 1];
      const Real c1 = v1.dot(v1);
      Vec3 r_left = r, t_left = samples.tangent[i - 1];
      if (c1 > 0) {
        r_left -= (2 / c1) * v1.dot(r) * v1;
        t_left -= (2 / c1) * v1.dot(t_left) * v1;
      }
      const Vec3 v2 = tangent - t_left;
      const Real c2 = v2.dot(v2);
      r = c2 > 0 ? Vec3(r_left - (2 / c2) * v2.dot(r_left) * v2) : r_left;
      // Keep r exactly perpendicular and unit against rounding drift.
      r = (r - r.dot(tangent) * tangent).normalized();
    }
    Frame& f = frames[i];
    f.origin = x;
    f.e1 = tangent;
    const Vec3 s = tangent.cross(r);
    if (samples.roll.empty()) {
      f.e2 = r;
      f.e3 = s;
    } else {
      const Real c = std::cos(samples.roll[i]), sn = std::sin(samples.roll[i]);
      f.e2 = c * r + sn * s;
      f.e3 = c * s - sn * r;
    }
  }
}

}  // namespace kodawari::ffd
