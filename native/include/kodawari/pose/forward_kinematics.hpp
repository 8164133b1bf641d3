// Armature-space pose matrices of a few bones from their channels, the way an armature
// evaluates a pose before constraints (docs/algorithms.md §3.7, "Predicting the inputs").
// Used to know a frame's parent bones before the host application evaluates that frame.
#pragma once

#include <cstdint>
#include <stdexcept>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::pose {

// How a bone's rotation channels are stored (the host's numbering: quaternion 0, the six
// Euler orders 1..6 as XYZ XZY YXZ YZX ZXY ZYX, axis-angle -1).
constexpr int kQuaternion = 0;
constexpr int kAxisAngle = -1;
constexpr int kEulerFirst = 1, kEulerLast = 6;

// What a child takes from its parent's pose scale (the host's inherit-scale modes that
// are supported here; others are refused by the caller).
enum class InheritScale : std::int32_t { kFull = 0, kAverage = 1, kNone = 2, kNoneLegacy = 3 };

struct BoneChannels {
  int parent = -1;              // index of the parent among the bones (earlier), or -1
  double rest[16] = {};         // armature-space rest matrix, row-major 4x4
  double channels[10] = {};     // location xyz, rotation (w x y z | x y z - | angle x y z), scale xyz
  int rotation_mode = kQuaternion;
  bool inherit_rotation = true;
  InheritScale inherit_scale = InheritScale::kFull;
};

// Writes each bone's armature-space pose matrix (row-major 4x4, 16 doubles per bone) into
// `out`. Parents must come before their children. Throws std::invalid_argument on a parent
// index that is not earlier, a rotation mode outside the numbering, a singular rest matrix, or
// NONE / AVERAGE scale inheritance with an inherited rotation (not modelled).
void forward_kinematics(const std::vector<BoneChannels>& bones, double* out);

}  // namespace kodawari::pose
