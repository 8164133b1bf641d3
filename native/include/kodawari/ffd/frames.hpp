// Frames Σ(M(t); e1, e2, e3) along the control curve (SEEDS §1, the "sub-axis").
// e1 is the unit tangent; (e2, e3) come from the rotation-minimising frame
// computed by double reflection (Wang, Jüttler, Zheng, Liu, ACM TOG 27(1), 2008,
// Algorithm "double reflection"), then rolled about e1 by the twist that the
// B-spline basis blends from the per-control-point values.
#pragma once

#include <optional>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/ffd/bspline.hpp"

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

// Unit tangent at t; where M'(t) vanishes (a cusp) the chord direction nearby.
Vec3 unit_tangent(const CubicBSpline& curve, Real t);

// Frames at t = i / (samples - 1), i = 0..samples-1, samples >= 2. `twist` is
// empty (no roll) or holds one angle per control point. `start_normal` is e2
// at t = 0 before the twist; it must be unit and perpendicular to the tangent.
FrameList rotation_minimising_frames(const CubicBSpline& curve, const std::vector<Real>& twist,
                                     const Vec3& start_normal, int samples);

}  // namespace kodawari::ffd
