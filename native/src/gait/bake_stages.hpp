// The stages of a gait bake, run in order by bake_gait (planner.cpp): the legs as the
// planner measures them, the body's track over the ground, the footfalls, the body's
// height and pitch, the body pose per frame, and the leg IK. Internal to src/gait.
#pragma once

#include <algorithm>
#include <array>
#include <vector>

#include "kodawari/gait/planner.hpp"

namespace kodawari::gait::stages {

using Vec2d = Eigen::Matrix<Real, 2, 1>;

constexpr int kMaxBones = 6;
constexpr Real kReachMargin = 0.93;  // IK targets stay inside 93% of what the chain reaches

inline Vec3 up() { return Vec3(0, 0, 1); }
inline Vec2d horizontal(const Vec3& v) { return Vec2d(v.x(), v.y()); }

// How far a chain reaches in each downward direction, sampled (leg_geometry.cpp).
struct Reach {
  std::vector<Real> table;
  Real at(Real angle) const;  // angle in [-pi, 0], CCW from +forward
};

// The legs as the planner measures them in the rig's rest pose (leg_geometry.cpp).
struct LegGeometry {
  std::array<LegChain, kLegCount> chains;
  std::array<Reach, kLegCount> reach_tables;
  std::array<Real, kLegCount> reach{};    // fore-aft reach around the rest foot, m
  std::array<Real, kLegCount> neutral{};  // rest foot fore-aft of its root
  std::array<Real, kLegCount> lateral{};  // rest foot sideways of its root
  std::array<Real, kLegCount> sole{};     // rest foot above the ground plane
  std::array<Vec3, kLegCount> root_rel{};  // leg root relative to the body head, rest
  std::array<int, kLegCount> bone_offset{};
  int bones = 0;
  Real ground_plane = 0;  // the lowest rest foot
  Real leg_length = 0;    // hind root above its foot: the Froude number's L
};
LegGeometry measure_legs(const Rig& rig, const GaitTable& table);

// Ground height at p: the heightfield, else the rest feet's plane.
Real ground_at(const BakeInput& in, const LegGeometry& legs, const Vec2d& p);

// The body's head and heading on the ground at one planner step.
struct Frame2 {
  Vec2d head;
  Vec2d heading;
};

// The body over the ground on the planner's fine grid (body_track.cpp): speed after the
// acceleration limit, distance, gait, head and heading (along the optional path).
struct BodyTrack {
  int substeps = 1;  // planner steps per frame
  Real dt = 0;       // planner step, s
  long last_step = 0, steps = 0;  // last frame's step; steps planned (with look-ahead)
  Vec2d forward = Vec2d::Zero();
  std::vector<Real> distance, speed;
  std::vector<int> gait;
  std::vector<Frame2> body;
  std::array<Vec3, kLegCount> root_rel{};

  long clamp_step(long k) const { return std::clamp(k, 0L, steps - 1); }
  const Frame2& at(long k) const { return body[clamp_step(k)]; }
  Vec2d root_at(int leg, long k) const;  // leg root on the ground plane
  Vec2d lateral_dir(long k) const;       // unit left of the heading
};
BodyTrack plan_body_track(const BakeInput& in, const LegGeometry& legs);

// Per frame and leg (frames x 4): the planner's foot, contact and swing lift
// (footfalls.cpp).
struct Footfalls {
  std::vector<Vec3> planned;
  std::vector<Real> contact;  // 1 planted, 0 swing
  std::vector<Real> lift;     // how far a swinging foot is above its ground path
};
Footfalls plan_footfalls(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track);

// Per frame: the body's bob and how far its fore and hind ends are lowered so every
// foot stays within reach (body_height.cpp).
struct BodyHeight {
  std::vector<Real> bob, drop_fore, drop_hind;
};
BodyHeight plan_body_height(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track,
                            const Footfalls& feet);

// Per frame: the body's rotation and head (armature space) (body_pose.cpp). Writes the
// body channels, gait, speed and headings of `out`.
struct BodyPoses {
  std::vector<Mat3> rotations;
  Vec3List heads;
};
BodyPoses pose_body(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track, const BodyHeight& height,
                    BakeOutput& out);

// The leg IK over all frames (leg_ik.cpp): writes angles, feet_planned and ik_error.
void solve_legs(const BakeInput& in, const LegGeometry& legs, const Footfalls& feet, const BodyPoses& poses,
                BakeOutput& out);

}  // namespace kodawari::gait::stages
