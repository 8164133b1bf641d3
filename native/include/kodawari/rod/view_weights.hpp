// Blend weights of keyed shapes from how similar the current condition is to
// each key (docs/algorithms.md §3.2):
//   w_i = s_i ^ p_i,  s = sum w_i,  if s >= 1: w_i /= s,  w_0 = 1 - min(s, 1)
// where s_i in [0, 1] is the similarity of key i (1 = exactly the keyed condition)
// and p_i > 0 its influence. The three conditions differ only in the similarity.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::rod {

// The seed's normalisation. Returns m + 1 weights, w[0] (base shape) first.
std::vector<Real> condition_weights(const std::vector<Real>& similarities, const std::vector<Real>& influences);

// VIEW: (dot(d_i, d) + 1) / 2 for unit directions (both in the reference joint's frame).
Real view_similarity(const Vec3& key_direction, const Vec3& view_direction);

// POSE: the cosine of the angle between two rotations, mapped to [0, 1]:
// (cos(theta) + 1) / 2, which for unit quaternions equals dot(q, q_key)^2.
Real pose_similarity(const Quat& key_rotation, const Quat& rotation);

// SPEED: exp(-|v - v_key| / max(v_key, 0.25 m/s)): 1 at the keyed speed, falling off
// relative to it, so a key at 5 m/s tolerates more than one at 0.5 m/s.
Real speed_similarity(Real key_speed, Real speed);

// The public `kodawari_native.view_weights`: key directions need not be unit
// (they are normalised); `view` must be non-zero.
std::vector<Real> view_weights(const Vec3List& key_directions, const std::vector<Real>& influences, const Vec3& view);

}  // namespace kodawari::rod
