// Chain shapes as per-joint rotations with fixed lengths (docs/algorithms.md
// §3.1). A shape holds, for every bone, its
// rotation relative to its rest frame in the parent bone (Blender's pose-bone
// `rotation_quaternion`), so blending never changes a bone's length; positions come
// back by forward kinematics from the chain root.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::rod {

// The static geometry of one chain, in the frames Blender uses.
struct ChainGeometry {
  // offsets[0]: the root bone's head in the kinematic parent's rest frame;
  // offsets[k] (1 <= k < n): bone k's head in bone k-1's rest frame;
  // offsets[n]: the last bone's tail in its own frame (0, length, 0).
  Vec3List offsets;
  // rest_rotations[k]: bone k's rest frame relative to its parent's rest frame.
  QuatList rest_rotations;

  std::size_t bone_count() const { return rest_rotations.size(); }
  // Length of the segment that starts at bone k's head (to the next head or the tip).
  Real segment_length(std::size_t k) const { return offsets[k + 1].norm(); }
  // That segment's direction in bone k's own frame.
  Vec3 segment_axis(std::size_t k) const { return offsets[k + 1] / offsets[k + 1].norm(); }
};

// Weighted blend of shapes (sum of weights 1): normalised sum of the quaternions,
// each flipped into the hemisphere of the identity so q and -q blend alike.
// shapes[i] is one shape (bone_count rotations); the base shape is the identity.
QuatList blend_shapes(const std::vector<QuatList>& key_shapes, const std::vector<Real>& weights,
                      std::size_t bone_count);
// The same blend without copies: key_shapes[i] points at key i's shape; writes `out`.
void blend_shapes_into(const QuatList* const* key_shapes, std::size_t key_count, const Real* weights,
                       std::size_t bone_count, QuatList& out);

// Forward kinematics in the anchor frame (the root bone's rest frame under its parent):
// bone frames and head positions, plus the tip position as heads[n].
void chain_forward_kinematics(const ChainGeometry& geometry, const QuatList& local_rotations, QuatList& frames,
                              Vec3List& heads);

}  // namespace kodawari::rod
