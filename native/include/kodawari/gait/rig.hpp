// A quadruped rig as the gait solver reads it (armature space, z up), its ground,
// and forward kinematics of baked channels.
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

// Empty when the rig can be solved, else a sentence naming what is wrong.
std::string validate_rig(const Rig& rig);

// The planar chain of one leg: (forward, up) coordinates of the rest pose.
LegChain make_chain(const Rig& rig, int leg);

// Feet and leg roots (armature space) of a pose given as baked channels: the report
// measures the baked Action with this.
void forward_kinematics(const Rig& rig, int frames, const Real* angles, const Real* body_location,
                        const Real* body_rotation, Real* feet, Real* roots);

}  // namespace kodawari::gait
