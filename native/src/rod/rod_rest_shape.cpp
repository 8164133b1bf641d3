// A rod's rest shape each frame (docs/algorithms.md §3.2, §3.4): the condition weights of
// its keys (view, pose, speed; Koyama & Igarashi 2013, "View-dependent control of elastic
// rod simulation"), their blend, and momentum control when the blend changes.
#include "kodawari/rod/rod_system.hpp"

#include <algorithm>
#include <limits>

#include "kodawari/rod/view_weights.hpp"
#include "rod_detail.hpp"

namespace kodawari::rod {

namespace detail {

// Rest particles in the anchor frame (see rod_system.hpp for the particle layout).
void rest_particles(const ChainGeometry& g, const QuatList& rest, Vec3List& x_rest, QuatList& q_rest) {
  const std::size_t n = g.bone_count();
  thread_local QuatList frames;
  thread_local Vec3List heads;
  chain_forward_kinematics(g, rest, frames, heads);
  x_rest.resize(n + 2);
  q_rest.resize(n + 2);
  x_rest[0] = -g.segment_length(0) * g.segment_axis(0);
  q_rest[0] = Quat::Identity();
  for (std::size_t j = 1; j <= n + 1; ++j) {
    x_rest[j] = heads[j - 1];
    q_rest[j] = frames[std::min(j - 1, n - 1)];
  }
}

// Bone frames of the current state: each particle's orientation turned so the bone
// axis lies along its actual segment.
void bone_frames(const ChainGeometry& g, const RodState& s, QuatList& frames) {
  const std::size_t n = g.bone_count();
  frames.resize(n);
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3 seg = s.x[k + 2] - s.x[k + 1];
    frames[k] = align_axis(s.q[k + 1], g.segment_axis(k), seg.normalized());
  }
}

}  // namespace detail

using namespace detail;

void RodSystem::begin_frame(std::size_t r, const FrameInput& input, const std::vector<Collider>& colliders,
                            bool reset) {
  (void)colliders;
  const RodDefinition& rod = rods_[r];
  RodState& s = states_[r];
  const std::size_t n = rod.bones.size();
  const Mat3 arm_linear = input.armature_matrix.block<3, 3>(0, 0);
  const Vec3 arm_translation = input.armature_matrix.block<3, 1>(0, 3);

  // Reference joint: view direction in its frame, its rotation, its speed.
  Quat ref_rotation;
  Vec3 ref_position;
  bone_transform(input.bone_matrices, static_cast<std::size_t>(rod.reference_bone), ref_rotation, ref_position);
  const Vec3 ref_world = arm_linear * ref_position + arm_translation;
  const Real speed = (s.initialised && !reset && input.frame_dt > 0)
                         ? (ref_world - s.reference_position).norm() / input.frame_dt
                         : Real(0);
  // A far move over a tiny step (a subframe) overflows to inf: the state stays finite, and
  // the largest speed weighs a speed key as inf did (speed_similarity gives 0).
  s.speed = speed <= std::numeric_limits<Real>::max() ? speed : std::numeric_limits<Real>::max();
  s.reference_position = ref_world;
  bool has_view = false;
  Vec3 view = Vec3::Zero();
  if (input.has_camera) {
    const Vec3 camera_armature = arm_linear.inverse() * (input.camera - arm_translation);
    view = ref_rotation.conjugate() * (camera_armature - ref_position);
    has_view = view.norm() > 1e-9;
    if (has_view) view.normalize();
  }
  // Per-thread buffers: a frame of a thousand rods allocates nothing here.
  thread_local std::vector<Real> similarities, influences;
  thread_local std::vector<const QuatList*> shapes;
  thread_local QuatList rest;
  similarities.resize(rod.keys.size());
  influences.resize(rod.keys.size());
  shapes.clear();
  for (std::size_t i = 0; i < rod.keys.size(); ++i) {
    const RodKey& key = rod.keys[i];
    influences[i] = key.influence;
    shapes.push_back(&key.shape);
    switch (key.condition) {
      case Condition::View:
        // No camera (or a camera inside the joint): view keys drop out, the base shape takes over.
        similarities[i] = has_view ? view_similarity(key.direction, view) : Real(0);
        break;
      case Condition::Pose:
        similarities[i] = pose_similarity(key.rotation, ref_rotation);
        break;
      case Condition::Speed:
        similarities[i] = speed_similarity(key.speed, s.speed);
        break;
    }
  }
  weights_[r] = condition_weights(similarities, influences);
  blend_shapes_into(shapes.data(), shapes.size(), weights_[r].data(), n, rest);

  if (reset || !s.initialised) {
    Quat parent_rotation;
    Vec3 parent_position;
    Mat3 parent_linear;
    bone_transform(input.bone_matrices, static_cast<std::size_t>(rod.parent_bone), parent_rotation, parent_position,
                   &parent_linear);
    s.anchor_position = parent_linear * rod.geometry.offsets[0] + parent_position;
    s.anchor_rotation = (parent_rotation * rod.geometry.rest_rotations[0]).normalized();
    Vec3List x_rest;
    QuatList q_rest;
    rest_particles(rod.geometry, rest, x_rest, q_rest);
    s.x.resize(n + 2);
    s.q.resize(n + 2);
    s.v.assign(n + 2, Vec3::Zero());
    s.omega.assign(n + 2, Vec3::Zero());
    s.prev_x.resize(n + 2);
    s.prev_q.resize(n + 2);
    for (std::size_t j = 0; j < n + 2; ++j) {
      s.x[j] = s.anchor_position + s.anchor_rotation * x_rest[j];
      s.q[j] = (s.anchor_rotation * q_rest[j]).normalized();
    }
    s.last_output.assign(n, Quat::Identity());
    s.time_accumulator = 0;
    s.rest_local = rest;
    s.window.steps = -1;
    s.window.reopen = false;
    s.initialised = true;
    return;
  }

  bool changed = false;
  for (std::size_t k = 0; k < n && !changed; ++k) changed = !(rest[k].coeffs() == s.rest_local[k].coeffs());
  if (changed) s.window.reopen = true;  // its energy was measured against the old rest shape
  if (changed && rod.params.momentum_control) {
    // Momentum control (the contribution of Koyama & Igarashi 2013, our formulation):
    // keep each joint's deviation from rest, E_k = rest_old_k⁻¹ · local_k, and re-apply it
    // on the new rest shape by forward kinematics from the root. Positions move
    // kinematically and velocities are untouched, so a rest shape that jumps adds no
    // momentum and nothing is flung.
    const Vec3List& offsets = rod.geometry.offsets;
    const QuatList& rest_rotations = rod.geometry.rest_rotations;
    QuatList frames, new_frames(n);
    bone_frames(rod.geometry, s, frames);
    const Quat tip_offset = frames[n - 1].conjugate() * s.q[n + 1];
    Vec3 head = s.x[1];
    for (std::size_t k = 0; k < n; ++k) {
      const Quat old_parent = k == 0 ? s.anchor_rotation : Quat(frames[k - 1] * rest_rotations[k]);
      const Quat new_parent = k == 0 ? s.anchor_rotation : Quat(new_frames[k - 1] * rest_rotations[k]);
      const Quat deviation = s.rest_local[k].conjugate() * (old_parent.conjugate() * frames[k]);
      new_frames[k] = (new_parent * rest[k] * deviation).normalized();
      if (k > 0) head += new_frames[k - 1] * offsets[k];
      s.x[k + 1] = head;
      s.q[k + 1] = new_frames[k];
    }
    s.x[n + 1] = head + new_frames[n - 1] * offsets[n];
    s.q[n + 1] = (new_frames[n - 1] * tip_offset).normalized();
  }
  s.rest_local = rest;
}

}  // namespace kodawari::rod
