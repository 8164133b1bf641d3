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
#include "kodawari/gait/rig.hpp"

namespace kodawari::gait {

struct BakeInput {
  GaitTable table;
  Rig rig;
  Real fps = 24;
  std::vector<Real> target_speed;  // per frame, m/s
  std::vector<int> gait_mode;      // per frame: -1 AUTO, else a Gait
  Real acceleration = 3;           // m/s^2
  int ccd_iterations = 64;
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

// Plans and solves every frame. Deterministic: the same input gives bit-identical output.
BakeOutput bake_gait(const BakeInput& input);

}  // namespace kodawari::gait
