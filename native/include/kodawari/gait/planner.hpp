// The gait planner and the whole-bake entry point (seed 3.1 and 3.3).
//
// A phase clock per leg; a planted foot is fixed in the world; a swinging foot
// travels from its lift-off point to a landing point sized by the seed's eq. 3.6 on a
// smooth path with the gait's height profile; body and leg roots move at the current
// speed with the gait's bob. Everything is planned on a fine fixed time grid, then
// sampled per frame and solved by CCD IK: one call plans and solves a whole bake.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/gait/ccd_ik.hpp"
#include "kodawari/gait/gait_table.hpp"

namespace kodawari::gait {

// One leg as it stands in the rig's rest pose, in armature space (z up).
struct LegRig {
  Vec3List heads;  // head of each bone, root first
  Vec3 tail = Vec3::Zero();  // tail of the last bone: the foot
  std::vector<Real> limit_min, limit_max, stiffness;  // radians, radians, ratio
};

struct Rig {
  Vec3 forward = Vec3(0, -1, 0);  // horizontal unit vector the animal faces (Blender: -Y)
  Vec3 body_head = Vec3::Zero();  // rest head of the body bone (carries root motion)
  Mat3 body_rest = Mat3::Identity();  // rest orientation of the body bone (armature space)
  std::array<LegRig, kLegCount> legs;  // LF, RF, LH, RH
};

// Ground heights on a regular grid in armature x, y (NaN where a ray missed).
struct Heightfield {
  Real x0 = 0, y0 = 0, cell = 1;
  int nx = 0, ny = 0;
  std::vector<Real> heights;  // ny rows of nx
  bool empty() const { return nx < 2 || ny < 2; }
  Real at(Real x, Real y) const;  // bilinear, clamped to the grid
};

struct BakeInput {
  GaitTable table;
  Rig rig;
  Real fps = 24;
  std::vector<Real> target_speed;  // per frame, m/s
  std::vector<int> gait_mode;      // per frame: -1 AUTO, else a Gait
  Real acceleration = 3;           // m/s^2
  int ccd_iterations = 24;
  Vec3List path;                   // optional polyline the body head follows
  Heightfield ground;              // optional; empty = flat at the rest feet
};

struct BakeOutput {
  int frames = 0, bones = 0;
  std::vector<Real> angles;         // frames x bones (LF bones, RF, LH, RH): hinge angles, radians
  std::vector<Real> body_location;  // frames x 3: body bone pose location (bone space)
  std::vector<Real> body_rotation;  // frames x 4: body bone pose quaternion (w, x, y, z)
  std::vector<Real> contacts;       // frames x 4: 1 planted, 0 swing
  std::vector<Real> feet_planned;   // frames x 4 x 3: planner's foot targets, armature space
  std::vector<Real> feet;           // frames x 4 x 3: feet of the solved pose
  std::vector<Real> roots;          // frames x 4 x 3: leg roots
  std::vector<Real> headings;       // frames x 3: unit forward of the body
  std::vector<int> gait;            // frames: the gait in use
  std::vector<Real> speed;          // frames: the body speed after the acceleration limit
  std::vector<Real> ik_error;       // frames x 4
  std::vector<Real> reach;          // 4: fore-aft reach of each leg, m
};

// Empty when the rig can be solved, else a sentence naming what is wrong.
std::string validate_rig(const Rig& rig);

// The planar chain of one leg: (forward, up) coordinates of the rest pose.
LegChain make_chain(const Rig& rig, int leg);

// Plans and solves every frame. Deterministic: the same input gives bit-identical output.
BakeOutput bake_gait(const BakeInput& input);

// Feet and leg roots (armature space) of a pose given as baked channels: the report
// measures the baked Action with this.
void forward_kinematics(const Rig& rig, int frames, const Real* angles, const Real* body_location,
                        const Real* body_rotation, Real* feet, Real* roots);

}  // namespace kodawari::gait
