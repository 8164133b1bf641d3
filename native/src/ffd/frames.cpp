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

Vec3 unit_tangent(const CubicBSpline& curve, Real t) {
  const Vec3 d = curve.first_derivative(t);
  const Real speed = d.norm();
  const Vec3 chord_hint = curve.control_points().back() - curve.control_points().front();
  const Real scale = chord_hint.norm() + (curve.control_points()[1] - curve.control_points()[0]).norm();
  if (speed > Real(1e-12) * scale) return d / speed;
  // A cusp: M'(t) = 0. Use the chord across a small parameter step instead.
  const Real h = Real(1e-4);
  const Vec3 chord = curve.point(std::min(Real(1), t + h)) - curve.point(std::max(Real(0), t - h));
  if (chord.norm() > 0) return chord.normalized();
  return (curve.control_points()[1] - curve.control_points()[0]).normalized();
}

FrameList rotation_minimising_frames(const CubicBSpline& curve, const std::vector<Real>& twist,
                                     const Vec3& start_normal, int samples) {
  FrameList frames(static_cast<std::size_t>(samples));
  const Real step = Real(1) / Real(samples - 1);
  Vec3 x_prev = curve.point(0);
  Vec3 t_prev = unit_tangent(curve, 0);
  Vec3 r_prev = start_normal;
  for (int i = 0; i < samples; ++i) {
    const Real t = i == samples - 1 ? Real(1) : i * step;
    Vec3 x = curve.point(t), tangent = unit_tangent(curve, t), r = r_prev;
    if (i > 0) {
      // Double reflection: reflect (r, t) in the bisector plane of x_prev -> x,
      // then in the plane that maps the reflected tangent onto the new tangent.
      const Vec3 v1 = x - x_prev;
      const Real c1 = v1.dot(v1);
      Vec3 r_left = r_prev, t_left = t_prev;
      if (c1 > 0) {
        r_left = r_prev - (2 / c1) * v1.dot(r_prev) * v1;
        t_left = t_prev - (2 / c1) * v1.dot(t_prev) * v1;
      }
      const Vec3 v2 = tangent - t_left;
      const Real c2 = v2.dot(v2);
      r = c2 > 0 ? Vec3(r_left - (2 / c2) * v2.dot(r_left) * v2) : r_left;
      // Keep r exactly perpendicular and unit against rounding drift.
      r = (r - r.dot(tangent) * tangent).normalized();
    }
    Frame& f = frames[static_cast<std::size_t>(i)];
    f.origin = x;
    f.e1 = tangent;
    const Vec3 s = tangent.cross(r);
    if (twist.empty()) {
      f.e2 = r;
      f.e3 = s;
    } else {
      const Real angle = curve.blend(twist, t);
      const Real c = std::cos(angle), sn = std::sin(angle);
      f.e2 = c * r + sn * s;
      f.e3 = c * s - sn * r;
    }
    x_prev = x;
    t_prev = tangent;
    r_prev = r;
  }
  return frames;
}

}  // namespace kodawari::ffd
