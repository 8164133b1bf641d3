// Clamped uniform cubic B-spline: the control curve M(t), t in [0, 1], of the
// control-axis FFD (docs/algorithms.md §1.1). The curve starts at the first control point and
// ends at the last; interior knots are evenly spaced.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::ffd {

// Throws std::invalid_argument naming `name` unless there are >= 4 finite points
// with no two consecutive ones coincident (the curve would lose its tangent).
void validate_control_points(const Vec3List& points, const char* name);

class CubicBSpline {
 public:
  explicit CubicBSpline(const Vec3List& control_points);

  int count() const { return static_cast<int>(points_.size()); }
  const Vec3List& control_points() const { return points_; }
  // Control points of M' (degree 2 on the knots U[1 .. n + 2]).
  const Vec3List& derivative_points() const { return first_; }

  Vec3 point(Real t) const;
  Vec3 first_derivative(Real t) const;
  Vec3 second_derivative(Real t) const;
  // Any per-control-point scalar (twist) blended by the same basis functions.
  Real blend(const std::vector<Real>& values, Real t) const;

 private:
  Real knot(int j) const;  // clamped uniform knot vector, j in [0, n + 3]
  int span(Real t) const;  // k with knot(k) <= t < knot(k + 1), 3 <= k <= n - 1

  Vec3List points_;
  Vec3List first_;   // control points of M' (degree 2), NURBS Book eq. 3.8
  Vec3List second_;  // control points of M'' (degree 1)
  int spans_ = 1;
};

// The four non-zero basis functions N_{first+j}(t) and their derivatives at t
// (NURBS Book A2.2 and eq. 2.7), for a clamped uniform cubic B-spline of
// `count` control points: M(t) = sum_j value[j] P_{first+j}.
struct CubicBasis {
  int first = 0;
  Real value[4] = {0, 0, 0, 0};
  Real slope[4] = {0, 0, 0, 0};
};
CubicBasis cubic_basis(int count, Real t);

// Arc length of the whole curve (Gauss-Legendre quadrature per knot span).
Real curve_length(const CubicBSpline& curve);

}  // namespace kodawari::ffd
