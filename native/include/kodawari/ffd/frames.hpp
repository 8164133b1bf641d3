// Frames Σ(M(t); e1, e2, e3) along the control curve (docs/algorithms.md §1.2, the "sub-axis").
// e1 is the unit tangent; (e2, e3) come from the rotation-minimising frame
// computed by double reflection (Wang, Jüttler, Zheng, Liu, ACM TOG 27(1), 2008,
// Algorithm "double reflection"), then rolled about e1 by the twist that the
// B-spline basis blends from the per-control-point values.
#pragma once

#include <optional>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/ffd/sampled_curve.hpp"

namespace kodawari::ffd {

struct Frame {
  Vec3 origin, e1, e2, e3;
};
using FrameList = std::vector<Frame, Eigen::aligned_allocator<Frame>>;

// The default start normal: the world axis least aligned with the tangent
// (lowest index on ties), made perpendicular to it.
Vec3 default_start_normal(const Vec3& tangent);

// `up` made perpendicular to `tangent` and unit; throws std::invalid_argument
// naming "up" when it is (nearly) parallel to the tangent or zero.
Vec3 start_normal_from_up(const Vec3& up, const Vec3& tangent);

// Carries `normal` (perpendicular to `from`) by the minimal rotation that turns
// unit tangent `from` into unit tangent `to`. Opposite tangents rotate by pi
// about `normal` itself, so the result stays deterministic.
Vec3 carry_normal(const Vec3& normal, const Vec3& from, const Vec3& to);

// Frames at the sampled points. `start_normal` is e2 at the first sample
// before the roll; it must be unit and perpendicular to the first tangent.
// Each step is one double reflection (Wang et al. 2008, Sec. 4), then every
// frame is rolled about e1 by the sampled twist.
void rotation_minimising_frames(const CurveSamples& samples, const Vec3& start_normal, FrameList& frames);

}  // namespace kodawari::ffd
