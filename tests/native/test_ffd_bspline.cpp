#include <gtest/gtest.h>

#include <stdexcept>

#include "ffd_test_curves.hpp"
#include "kodawari/ffd/bspline.hpp"

using namespace kodawari;
using namespace kodawari::ffd;

TEST(FfdBSpline, InterpolatesTheEndControlPointsWithTangentsAlongTheEndLegs) {
  const Vec3List points = fixtures::s_curve(7);
  const CubicBSpline curve(points);
  EXPECT_LT((curve.point(0) - points.front()).norm(), 1e-12);
  EXPECT_LT((curve.point(1) - points.back()).norm(), 1e-12);
  EXPECT_LT((curve.first_derivative(0).normalized() - (points[1] - points[0]).normalized()).norm(), 1e-12);
  EXPECT_LT((curve.first_derivative(1).normalized() - (points[6] - points[5]).normalized()).norm(), 1e-12);
}

TEST(FfdBSpline, EvenlySpacedCollinearPointsGiveAStraightLineOfTheSameLength) {
  const CubicBSpline curve(fixtures::straight_axis(5, 4));
  EXPECT_NEAR(curve_length(curve), 4.0, 1e-12);
  for (Real t : {0.1, 0.37, 0.5, 0.93}) EXPECT_NEAR(curve.point(t).y(), 0.0, 1e-15);
}

TEST(FfdBSpline, DerivativesMatchFiniteDifferences) {
  const CubicBSpline curve(fixtures::helix(12));
  const Real h = 1e-6;
  for (Real t : {0.05, 0.2, 0.4999, 0.61, 0.95}) {
    const Vec3 d1 = (curve.point(t + h) - curve.point(t - h)) / (2 * h);
    const Vec3 d2 = (curve.first_derivative(t + h) - curve.first_derivative(t - h)) / (2 * h);
    EXPECT_LT((curve.first_derivative(t) - d1).norm(), 1e-5 * d1.norm()) << t;
    EXPECT_LT((curve.second_derivative(t) - d2).norm(), 1e-5 * d2.norm()) << t;
  }
}

TEST(FfdBSpline, BasisFunctionsSumToOneAndReproduceDeBoor) {
  const Vec3List points = fixtures::helix(9);
  const CubicBSpline curve(points);
  for (int i = 0; i <= 200; ++i) {
    const Real t = i / 200.0;
    const CubicBasis basis = cubic_basis(9, t);
    Real sum = 0, slope_sum = 0;
    Vec3 p = Vec3::Zero(), d = Vec3::Zero();
    for (int j = 0; j < 4; ++j) {
      EXPECT_GE(basis.value[j], -1e-15);
      sum += basis.value[j];
      slope_sum += basis.slope[j];
      p += basis.value[j] * points[basis.first + j];
      d += basis.slope[j] * points[basis.first + j];
    }
    EXPECT_NEAR(sum, 1.0, 1e-14);
    EXPECT_NEAR(slope_sum, 0.0, 1e-12);
    EXPECT_LT((p - curve.point(t)).norm(), 1e-12) << t;
    EXPECT_LT((d - curve.first_derivative(t)).norm(), 1e-10) << t;
  }
}

TEST(FfdBSpline, HelixArcLengthMatchesADensePolyline) {
  const CubicBSpline curve(fixtures::helix());
  Real polyline = 0;
  const int steps = 200000;
  for (int i = 0; i < steps; ++i) polyline += (curve.point((i + 1.0) / steps) - curve.point(Real(i) / steps)).norm();
  EXPECT_NEAR(curve_length(curve), polyline, 1e-7 * polyline);
}

TEST(FfdBSpline, RejectsTooFewNonFiniteOrCoincidentControlPoints) {
  EXPECT_THROW(CubicBSpline{fixtures::straight_axis(3)}, std::invalid_argument);
  Vec3List coincident = fixtures::straight_axis(5);
  coincident[3] = coincident[2];
  EXPECT_THROW(CubicBSpline{coincident}, std::invalid_argument);
  Vec3List nan = fixtures::straight_axis(5);
  nan[1].y() = std::nan("");
  EXPECT_THROW(CubicBSpline{nan}, std::invalid_argument);
  try {
    CubicBSpline{coincident};
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("control_points"), std::string::npos);
  }
}
