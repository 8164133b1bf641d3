// Cyclic Coordinate Descent for one leg in its sagittal plane (seed 3.2).
// Horse legs do not abduct, so every joint is a hinge about the body's lateral axis
// and the chain is planar: coordinates (f, u) = (forward, up).
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::gait {

using Vec2 = Eigen::Matrix<Real, 2, 1>;

// A chain of 2..6 bones. A pose angle theta_k is the bone's rotation from its rest
// pose, right-handed about the lateral axis (forward x up), so a positive angle swings
// a downward bone's tip backward, as the seed's "counter-clockwise with the horse
// running to the left". Child bones inherit their parent's rotation.
struct LegChain {
  Vec2 root = Vec2::Zero();          // head of the first bone, (f, u)
  std::vector<Real> lengths;         // bone lengths in the sagittal plane
  std::vector<Real> rest_direction;  // each bone's rest direction, radians CCW from +f
  std::vector<Real> limit_min;       // radians, pose-relative
  std::vector<Real> limit_max;
  std::vector<Real> stiffness;       // 0..1: share of each CCD rotation a joint takes

  int size() const { return static_cast<int>(lengths.size()); }
  Real length() const;
};

// Joint positions (n + 1 points, root first, foot last) for the pose `angles`.
void chain_points(const LegChain& chain, const Real* angles, Vec2* points);
Vec2 chain_foot(const LegChain& chain, const Real* angles);

struct CcdResult {
  Real error = 0;  // distance foot - target after the solve
  int iterations = 0;
};

// Solves in place: `angles` holds the previous frame's pose (warm start) and receives
// the new one. From the last bone up, each joint turns so the line from it to the foot
// points at the target, scaled by its stiffness and clamped to its limits. An
// unreachable target leaves the chain stretched towards it: stable, never NaN.
// A stalled stiff solve is finished by plain CCD (stiffness 1) from where it stalled.
// With allow_restart (a planted foot, which must be reached) a solve still more than
// 1 mm away is retried from cold starts (limits freed, rest pose, middle of the
// limits), keeping the closest. A swinging foot gets no cold restart, so it never
// jumps between branches (the bake's leg IK crosses branches smoothly: leg_ik.cpp).
CcdResult solve_ccd(const LegChain& chain, const Vec2& target, int iterations, Real tolerance, Real* angles,
                    bool allow_restart = true);

// Damped least squares for a planted foot (docs/algorithms.md §4.8; Wampler
// 1986, Nakamura & Hanafusa 1986): from the previous pose, Gauss-Newton steps with the
// joints weighted by their stiffness, dtheta = S J^T (J S J^T + lambda^2 I)^-1 e. Each
// step is the least weighted change that moves the foot towards the target, so the
// pose follows a moving target continuously: it never jumps to another leg
// configuration the way a CCD sweep can. A joint that reaches a limit is held there.
// `soften` false: no slowing near the limits (a second try where the softened solve
// stalls with most joints near their limits).
CcdResult solve_dls(const LegChain& chain, const Vec2& target, int iterations, Real tolerance, Real* angles,
                    bool soften = true);

// How far the chain reaches from its root along `direction` (unit, (f, u)) within its
// limits: the foot's distance along the direction after solving towards a far target.
Real directional_reach(const LegChain& chain, const Vec2& direction);

}  // namespace kodawari::gait
