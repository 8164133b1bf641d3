// A stance's joint motion evened out over its frames (stance_even.cpp,
// docs/algorithms.md §4.8, "The fastest joint of a stance"). Internal to src/gait.
#pragma once

#include <vector>

#include "bake_stages.hpp"

namespace kodawari::gait::stages {

// Re-solves the frames `angles` (count x n, frame-major) of one leg for the least largest
// change of a joint between frames, each frame's foot on `goals[i]`. `before` (fixed) is
// the pose before the first frame, `after` (fixed, or null) the pose after the last;
// `counted[j]` marks the changes whose peak is lowered (change j goes into frame j, change
// `count` into `after`): the others are only kept from growing past their own largest.
// Iteratively reweighted least squares (Lawson) with a constrained Gauss-Newton step per
// round, the norm's exponent raised from 2 to `last_exponent` (16: near the largest
// change itself). Keeps the result (its misses in `errors`) only if its largest counted change is
// smaller and every foot is within `allowed[i]` (or as close as before).
bool even_stance(const LegChain& chain, const Vec2d* goals, int count, const Real* before, const Real* after,
                 const std::vector<char>& counted, std::vector<Real>& angles, std::vector<Real>& errors,
                 Real tolerance, const std::vector<Real>& allowed, int iterations, Real last_exponent = 16);

}  // namespace kodawari::gait::stages
