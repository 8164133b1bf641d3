// CCD IK per leg: reaches, respects limits, stable when unreachable, stiffness order.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "kodawari/gait/ccd_ik.hpp"

using namespace kodawari;
using namespace kodawari::gait;

namespace {
LegChain straight_down(int n, Real limit = 2.0) {
  LegChain c;
  for (int k = 0; k < n; ++k) {
    c.lengths.push_back(0.4);
    c.rest_direction.push_back(-kPi / 2);
    c.limit_min.push_back(-limit);
    c.limit_max.push_back(limit);
    c.stiffness.push_back(1.0);
  }
  return c;
}
}  // namespace

TEST(GaitCcd, ReachesAReachableTargetForEveryChainLength) {
  for (int n = 2; n <= 6; ++n) {
    LegChain c = straight_down(n);
    const Vec2 target(0.3, -0.3 * n);
    std::vector<Real> angles(n, 0.0);
    const CcdResult r = solve_ccd(c, target, 200, 1e-6, angles.data());
    EXPECT_LT(r.error, 1e-4) << n << " bones";
    EXPECT_LT((chain_foot(c, angles.data()) - target).norm(), 1e-4);
  }
}

TEST(GaitCcd, UnreachableTargetGivesAStableStretchedPoseNeverNaN) {
  LegChain c = straight_down(4);
  std::vector<Real> angles(4, 0.0);
  const Vec2 far(10.0, -10.0);
  const CcdResult first = solve_ccd(c, far, 50, 1e-6, angles.data());
  const CcdResult again = solve_ccd(c, far, 50, 1e-6, angles.data());  // no oscillation: only closer
  EXPECT_LE(again.error, first.error + 1e-12);
  for (int k = 0; k < 4; ++k) EXPECT_TRUE(std::isfinite(angles[k]));
  const Vec2 foot = chain_foot(c, angles.data());
  EXPECT_NEAR(foot.norm(), 1.6, 0.01);  // stretched out...
  EXPECT_GT(foot.normalized().dot(far.normalized()), 0.999);  // ...towards the target
  // Degenerate inputs: target on the root, NaN warm start.
  angles.assign(4, std::nan(""));
  const CcdResult r = solve_ccd(c, Vec2(0, 0), 20, 1e-6, angles.data());
  for (Real a : angles) EXPECT_TRUE(std::isfinite(a));
  EXPECT_TRUE(std::isfinite(r.error));
}

TEST(GaitCcd, HingeLimitsHold) {
  LegChain c = straight_down(4, 0.3);
  std::vector<Real> angles(4, 0.0);
  solve_ccd(c, Vec2(1.2, -0.2), 100, 1e-6, angles.data());
  for (int k = 0; k < 4; ++k) {
    EXPECT_GE(angles[k], -0.3);
    EXPECT_LE(angles[k], 0.3);
  }
}

TEST(GaitCcd, StiffnessMakesTheUpperJointsLead) {
  // Plain CCD bends the joints nearest the foot first (seed 3.2); stiffness
  // (0.1, 0.3, 0.5, 1.0) from the top slows the hoof... and (0.02, 0.1, 1.0, 0.1)
  // lets the third bone lead.
  LegChain plain = straight_down(4);
  LegChain stiff = plain;
  stiff.stiffness = {0.02, 0.1, 1.0, 0.1};
  const Vec2 target(0.6, -1.2);
  std::vector<Real> a(4, 0.0), b(4, 0.0);
  solve_ccd(plain, target, 1, 0, a.data(), false);
  solve_ccd(stiff, target, 1, 0, b.data(), false);
  EXPECT_GT(std::abs(a[3]), std::abs(a[2]));  // plain: the last bone turns most
  EXPECT_GT(std::abs(b[2]), std::abs(b[3]));  // stiff: the third bone leads
}

TEST(GaitCcd, WarmStartNeedsFewerSweeps) {
  LegChain c = straight_down(4);
  c.stiffness = {0.1, 0.3, 0.5, 1.0};
  std::vector<Real> warm(4, 0.0);
  solve_ccd(c, Vec2(0.30, -1.30), 500, 1e-7, warm.data());
  std::vector<Real> cold(4, 0.0);
  const CcdResult from_cold = solve_ccd(c, Vec2(0.32, -1.30), 500, 1e-7, cold.data());
  const CcdResult from_warm = solve_ccd(c, Vec2(0.32, -1.30), 500, 1e-7, warm.data());
  EXPECT_LT(from_warm.error, 1e-6);
  EXPECT_LT(from_warm.iterations, from_cold.iterations);
}

TEST(GaitCcd, DirectionalReachIsTheStretchedLength) {
  LegChain c = straight_down(3);
  EXPECT_NEAR(directional_reach(c, Vec2(0, -1)), 1.2, 1e-3);
}
