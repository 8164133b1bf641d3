// Closest curve point to a vertex, for the bind step (docs/algorithms.md §1.3): a coarse
// polyline search picks the basin, then Newton on the exact spline refines t.
#pragma once

#include "kodawari/common.hpp"
#include "kodawari/ffd/bspline.hpp"

namespace kodawari::ffd {

class ClosestPointFinder {
 public:
  explicit ClosestPointFinder(const CubicBSpline& curve);
  // t in [0, 1] of the curve point closest to p. Ties between equally close
  // coarse segments go to the lowest t, so the answer is deterministic.
  Real parameter(const Vec3& p) const;

 private:
  const CubicBSpline& curve_;
  Vec3List coarse_;
};

}  // namespace kodawari::ffd
