#include "kodawari/ffd/closest_point.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kodawari::ffd {

ClosestPointFinder::ClosestPointFinder(const CubicBSpline& curve) : curve_(curve) {
  // 16 chords per knot span follow the curve closely enough that the closest
  // chord lies in the basin of the true closest point.
  const int segments = std::max(64, 16 * (curve.count() - 3));
  coarse_.resize(static_cast<std::size_t>(segments) + 1);
  for (int i = 0; i <= segments; ++i) coarse_[static_cast<std::size_t>(i)] = curve.point(Real(i) / segments);
}

Real ClosestPointFinder::parameter(const Vec3& p) const {
  const int segments = static_cast<int>(coarse_.size()) - 1;
  Real best = std::numeric_limits<Real>::infinity();
  Real t0 = 0;
  for (int j = 0; j < segments; ++j) {
    const Vec3& a = coarse_[static_cast<std::size_t>(j)];
    const Vec3 ab = coarse_[static_cast<std::size_t>(j) + 1] - a;
    const Real len2 = ab.squaredNorm();
    const Real s = len2 > 0 ? std::clamp((p - a).dot(ab) / len2, Real(0), Real(1)) : Real(0);
    const Real d2 = (a + s * ab - p).squaredNorm();
    if (d2 < best) {
      best = d2;
      t0 = (j + s) / segments;
    }
  }
  // Newton on f(t) = (M(t) - p) . M'(t) = 0; Gauss-Newton step where the
  // Hessian is not positive (far from the curve on its concave side).
  Real t = t0;
  for (int iteration = 0; iteration < 20; ++iteration) {
    const Vec3 r = curve_.point(t) - p;
    const Vec3 d1 = curve_.first_derivative(t);
    const Real f = r.dot(d1);
    Real slope = d1.dot(d1) + r.dot(curve_.second_derivative(t));
    if (!(slope > 0)) slope = d1.dot(d1);
    if (!(slope > 0)) break;
    const Real next = std::clamp(t - f / slope, Real(0), Real(1));
    const bool converged = std::abs(next - t) < Real(1e-13);
    t = next;
    if (converged) break;
  }
  if ((curve_.point(t) - p).squaredNorm() > (curve_.point(t0) - p).squaredNorm()) t = t0;
  return t;
}

}  // namespace kodawari::ffd
