// The control curve sampled at evenly spaced t with basis weights computed
// once: re-sampling a moved curve each frame is then a few multiply-adds per
// sample instead of a de Boor evaluation.
#pragma once

#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/ffd/bspline.hpp"

namespace kodawari::ffd {

struct CurveSamples {
  Vec3List origin;          // M(t_i)
  Vec3List tangent;         // unit M'(t_i); across a cusp, the chord of the neighbours
  std::vector<Real> roll;   // blended twist at t_i (empty when there is no twist)
};

class UniformCurveSampler {
 public:
  // t_i = i / (samples - 1), i = 0..samples-1; count >= 4 control points, samples >= 2.
  UniformCurveSampler(int count, int samples);

  int count() const { return count_; }
  int samples() const { return static_cast<int>(basis_.size()); }

  // `points` has count() entries; `twist` is empty or has count() entries.
  void sample(const Vec3List& points, const std::vector<Real>& twist, CurveSamples& out) const;

 private:
  int count_;
  std::vector<CubicBasis> basis_;
};

}  // namespace kodawari::ffd
