#include "kodawari/rod/rod_system.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include <glm/gtc/noise.hpp>
#include <glm/vec2.hpp>

#include "kodawari/parallel.hpp"
#include "kodawari/rod/view_weights.hpp"

namespace kodawari::rod {

namespace {

// Ghost and root are kinematic; their larger weight in each group fit makes the
// root bone hold its rest direction relative to the parent more firmly.
constexpr Real kKinematicWeight = 4.0;
// Wind acts as drag towards the wind velocity: a = kWindDrag * (wind - v).
constexpr Real kWindDrag = 1.5;
// Gust frequency (Hz) and strength of the GLM Perlin noise that modulates the wind.
constexpr Real kGustFrequency = 0.7;
constexpr Real kGustAmount = 0.6;
// Substep rate unit: `substeps` counts substeps per 1/24 s, whatever the scene's fps.
constexpr Real kSubstepUnit = 24.0;
constexpr long kMaxSubstepsPerFrame = 4096;
// Rods per work chunk (threads take chunks as they go): about 0.2 ms of work at 16 bones.
constexpr std::size_t kRodsPerChunk = 16;

bool finite(const Vec3& v) { return v.allFinite(); }

// q / |q| with one division (Eigen's normalized() divides every coefficient): the
// substep loop normalises three quaternions per particle.
inline Quat unit(const Quat& q) {
  Quat out;
  out.coeffs() = q.coeffs() * (Real(1) / std::sqrt(q.coeffs().squaredNorm()));
  return out;
}
bool finite(const Quat& q) { return q.coeffs().allFinite(); }

// Spin integration to first order, q <- normalise([1, ω dt / 2] q), and its exact inverse
// ω = 2 vec(dq) / (w(dq) dt): consistent with each other and free of sin/cos/atan2, which
// matters at tens of thousands of particles per substep (dt ω is small at these rates).
Quat spin(const Quat& q, const Vec3& rotation_vector) {
  const Vec3 half = rotation_vector / 2;
  return unit(Quat(1, half.x(), half.y(), half.z()) * q);
}

// Angular velocity that turns `from` into `to` in dt (inverse of spin).
Vec3 angular_velocity(const Quat& from, const Quat& to, Real dt) {
  Quat dq = to * from.conjugate();
  if (dq.w() < 0) dq.coeffs() = -dq.coeffs();
  if (dq.w() < 1e-6) return Vec3::Zero();  // a half turn in one substep: no meaningful spin
  return dq.vec() * (2 / (dq.w() * dt));
}

}  // namespace

void bone_transform(const float* bone_matrices, std::size_t index, Quat& rotation, Vec3& position,
                    Eigen::Matrix<Real, 3, 3>* linear) {
  const Eigen::Map<const Eigen::Matrix<float, 4, 4>> m(bone_matrices + 16 * index);
  Mat3 l = m.block<3, 3>(0, 0).cast<Real>();
  position = m.block<3, 1>(0, 3).cast<Real>();
  if (linear) *linear = l;
  // Remove scale: normalise the columns (pose bones are rotation + uniform scale here).
  for (int c = 0; c < 3; ++c) {
    const Real n = l.col(c).norm();
    if (n > 1e-12) l.col(c) /= n;
  }
  rotation = Quat(l).normalized();
}

RodSystem::RodSystem(std::size_t bone_count, unsigned threads) : bone_count_(bone_count), threads_(threads) {}

std::size_t RodSystem::add_rod(RodDefinition rod) {
  const std::size_t n = rod.bones.size();
  auto fail = [](const std::string& why) { throw std::invalid_argument(why); };
  if (n == 0) fail("a rod needs at least one joint (got 0 bones)");
  if (rod.geometry.offsets.size() != n + 1) fail("offsets must have one row per bone plus the tip");
  if (rod.geometry.rest_rotations.size() != n) fail("rest_rotations must have one row per bone");
  auto valid_bone = [&](int b) { return b >= 0 && static_cast<std::size_t>(b) < bone_count_; };
  if (!valid_bone(rod.parent_bone)) fail("parent_bone is not a bone index of this armature");
  if (!valid_bone(rod.reference_bone)) fail("reference_bone is not a bone index of this armature");
  for (int b : rod.bones) {
    if (!valid_bone(b)) fail("bones contains an index outside the armature");
    if (b == rod.parent_bone) fail("the parent bone cannot be part of its own rod");
  }
  for (const Vec3& o : rod.geometry.offsets) {
    if (!finite(o)) fail("offsets contain NaN or inf");
  }
  for (std::size_t k = 0; k < n; ++k) {
    if (!(rod.geometry.segment_length(k) > 1e-6)) fail("bone " + std::to_string(k) + " of the rod has zero length");
    Quat& q = rod.geometry.rest_rotations[k];
    if (!finite(q) || q.norm() < 1e-6) fail("rest_rotations contain NaN or a zero quaternion");
    q.normalize();
  }
  RodParams& p = rod.params;
  if (!(p.stiffness > 0 && p.stiffness <= 1)) fail("stiffness must be in (0, 1]");
  if (!(p.damping >= 0) || !std::isfinite(p.damping)) fail("damping must be >= 0");
  if (!std::isfinite(p.gravity)) fail("gravity must be finite");
  if (p.substeps < 1 || p.substeps > 64) fail("substeps must be in 1..64");
  if (p.iterations < 1 || p.iterations > 64) fail("iterations must be in 1..64");
  if (!(p.radius >= 0) || !std::isfinite(p.radius)) fail("radius must be >= 0");
  if (!finite(p.wind)) fail("wind must be finite");
  for (RodKey& key : rod.keys) {
    if (!(key.influence > 0) || !std::isfinite(key.influence)) fail("key influences must be > 0");
    if (key.shape.size() != n) fail("every key shape needs one rotation per bone");
    for (Quat& q : key.shape) {
      if (!finite(q) || q.norm() < 1e-6) fail("a key shape contains NaN or a zero quaternion");
      q.normalize();
    }
    if (key.condition == Condition::View) {
      if (!finite(key.direction) || key.direction.norm() < 1e-9) fail("a view key has a zero or NaN direction");
      key.direction.normalize();
    } else if (key.condition == Condition::Pose) {
      if (!finite(key.rotation) || key.rotation.norm() < 1e-6) fail("a pose key has a NaN or zero rotation");
      key.rotation.normalize();
    } else if (!(key.speed >= 0) || !std::isfinite(key.speed)) {
      fail("a speed key needs a speed >= 0");
    }
  }
  rods_.push_back(std::move(rod));
  states_.emplace_back();
  weights_.emplace_back(rods_.back().keys.size() + 1, Real(0));
  weights_.back()[0] = 1;
  return rods_.size() - 1;
}

void RodSystem::set_colliders(std::vector<ColliderDefinition> colliders) {
  for (const auto& c : colliders) {
    if (c.bone < 0 || static_cast<std::size_t>(c.bone) >= bone_count_) {
      throw std::invalid_argument("a collider bone index is outside the armature");
    }
    if (!(c.radius >= 0) || !std::isfinite(c.radius) || !(c.length >= 0) || !finite(c.offset)) {
      throw std::invalid_argument("collider radius and length must be finite and >= 0");
    }
  }
  colliders_ = std::move(colliders);
}

std::vector<Collider> RodSystem::world_colliders(const FrameInput& input) const {
  std::vector<Collider> out;
  out.reserve(colliders_.size());
  for (const auto& c : colliders_) {
    Quat r;
    Vec3 t;
    bone_transform(input.bone_matrices, static_cast<std::size_t>(c.bone), r, t);
    Collider w;
    w.start = t + r * c.offset;
    w.end = c.capsule ? Vec3(w.start + r * Vec3(0, c.length, 0)) : w.start;
    w.radius = c.radius;
    out.push_back(w);
  }
  return out;
}

namespace {

// Rest particles in the anchor frame (see the header for the particle layout).
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

}  // namespace

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
  s.speed = (s.initialised && !reset && input.frame_dt > 0) ? (ref_world - s.reference_position).norm() / input.frame_dt
                                                            : Real(0);
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
    s.initialised = true;
    return;
  }

  bool changed = false;
  for (std::size_t k = 0; k < n && !changed; ++k) changed = !(rest[k].coeffs() == s.rest_local[k].coeffs());
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

namespace {

// Per-thread work arrays of simulate(), reused from rod to rod and frame to frame:
// the substep loop allocates nothing.
struct SimulationScratch {
  Vec3List x_rest;
  QuatList q_rest, q_rest_conjugate, new_q;
  std::vector<Real> lengths, inverse_hits;
  // Per group c (members c-1, c, c+1 clipped to the chain): member weights w_i / mass,
  // rest offsets from the rest centroid r_i = x̄_i - c̄, and w_i r_i (so that
  // A = Σ w_i (x_i - c)(x̄_i - c̄)ᵀ = Σ x_i (w_i r_i)ᵀ, because Σ w_i r_i = 0).
  std::vector<Real> group_weights;   // 3 per group: w_i / mass
  std::vector<Real> group_ellipsoid; // 3 per group: w_i e (groups with a kinematic member)
  Vec3List group_rest, group_weighted_rest;  // 3 per group
  std::vector<Mat3, Eigen::aligned_allocator<Mat3>> orientation_terms;
  QuatList orientation_quats;
  Vec3List displacement;
};

SimulationScratch& simulation_scratch() {
  thread_local SimulationScratch scratch;
  return scratch;
}

// The rotation matrix of a unit quaternion (as Eigen's toRotationMatrix, inlined here).
inline Mat3 rotation_matrix(const Quat& q) {
  return q.toRotationMatrix();
}

}  // namespace

void RodSystem::simulate(std::size_t r, const FrameInput& input, const std::vector<Collider>& colliders) {
  const RodDefinition& rod = rods_[r];
  const RodParams& p = rod.params;
  RodState& s = states_[r];
  const std::size_t n = rod.bones.size();
  const std::size_t count = n + 2;

  // Kinematic anchor at the end of this frame.
  Quat parent_rotation;
  Vec3 parent_position;
  Mat3 parent_linear;
  bone_transform(input.bone_matrices, static_cast<std::size_t>(rod.parent_bone), parent_rotation, parent_position,
                 &parent_linear);
  const Vec3 anchor_end = parent_linear * rod.geometry.offsets[0] + parent_position;
  Quat anchor_end_rotation = (parent_rotation * rod.geometry.rest_rotations[0]).normalized();
  if (anchor_end_rotation.dot(s.anchor_rotation) < 0) anchor_end_rotation.coeffs() = -anchor_end_rotation.coeffs();
  const Vec3 anchor_start = s.anchor_position;
  const Quat anchor_start_rotation = s.anchor_rotation;

  // Fixed substep rate, independent of the scene's frame rate; leftover time carries over.
  const Real rate = kSubstepUnit * p.substeps;
  s.time_accumulator += std::max(input.frame_dt, Real(0));
  long steps = static_cast<long>(std::floor(s.time_accumulator * rate + 1e-9));
  s.time_accumulator = std::max(Real(0), s.time_accumulator - Real(steps) / rate);
  steps = std::min(steps, kMaxSubstepsPerFrame);

  // Everything below that depends only on the rest shape is computed once per frame.
  SimulationScratch& w = simulation_scratch();
  rest_particles(rod.geometry, s.rest_local, w.x_rest, w.q_rest);
  const Vec3List& x_rest = w.x_rest;
  const QuatList& q_rest = w.q_rest;
  w.q_rest_conjugate.resize(count);
  for (std::size_t j = 0; j < count; ++j) w.q_rest_conjugate[j] = q_rest[j].conjugate();
  w.lengths.resize(n);
  for (std::size_t k = 0; k < n; ++k) w.lengths[k] = rod.geometry.segment_length(k);
  const Real ellipsoid = [&] {
    Real mean = 0;
    for (Real l : w.lengths) mean += l;
    mean /= Real(n);
    return (mean * mean) / 5;  // a sphere of radius one segment: a²/5
  }();
  // Particle j >= 2 belongs to the groups j-1, j and j+1 (those that exist): the Jacobi average.
  w.inverse_hits.assign(count, Real(0));
  for (std::size_t j = 2; j < count; ++j) w.inverse_hits[j] = Real(1) / Real(j + 1 < count ? 3 : 2);
  w.group_weights.assign(3 * count, Real(0));
  w.group_ellipsoid.assign(3 * count, Real(0));
  w.group_rest.assign(3 * count, Vec3::Zero());
  w.group_weighted_rest.assign(3 * count, Vec3::Zero());
  for (std::size_t c = 1; c < count; ++c) {
    const std::size_t lo = c - 1;
    const std::size_t members = std::min(c + 1, count - 1) - lo + 1;
    Real mass = 0;
    Vec3 c_rest = Vec3::Zero();
    for (std::size_t i = 0; i < members; ++i) {
      // Ghost and root are kinematic: heavier in the fit.
      const Real wi = (lo + i) <= 1 ? kKinematicWeight : Real(1);
      mass += wi;
      c_rest += wi * x_rest[lo + i];
      w.group_ellipsoid[3 * c + i] = wi * ellipsoid;
    }
    c_rest /= mass;
    for (std::size_t i = 0; i < members; ++i) {
      const Real wi = (lo + i) <= 1 ? kKinematicWeight : Real(1);
      w.group_weights[3 * c + i] = wi / mass;
      w.group_rest[3 * c + i] = x_rest[lo + i] - c_rest;
      w.group_weighted_rest[3 * c + i] = wi * w.group_rest[3 * c + i];
    }
  }

  const Mat3 world_to_armature = input.armature_matrix.block<3, 3>(0, 0).inverse();
  const Vec3 gravity = world_to_armature * (input.gravity * p.gravity);
  const Real dt = 1 / rate;
  const Real inverse_dt = rate;
  const Real decay = std::exp(-p.damping * dt);
  const Real stiffness = p.stiffness;

  w.orientation_terms.resize(count);
  w.orientation_quats.resize(count);
  w.displacement.resize(count);
  w.new_q.resize(count);
  Vec3* x = s.x.data();
  Quat* q = s.q.data();
  for (long step = 1; step <= steps; ++step) {
    const Real f = Real(step) / Real(steps);
    const Vec3 anchor = anchor_start + f * (anchor_end - anchor_start);
    const Quat anchor_rotation = anchor_start_rotation.slerp(f, anchor_end_rotation).normalized();
    x[0] = anchor + anchor_rotation * x_rest[0];
    q[0] = anchor_rotation;
    x[1] = anchor;

    // Wind with gusts: GLM Perlin noise over time, one noise line per rod (deterministic).
    const bool windy = p.wind.squaredNorm() > 0;
    Vec3 wind = Vec3::Zero();
    if (windy) {
      const Real t = input.time - (1 - f) * input.frame_dt;
      const Real gust = 1 + kGustAmount * Real(glm::perlin(glm::dvec2(t * kGustFrequency, 0.37 * Real(r) + 0.5)));
      wind = world_to_armature * (p.wind * gust);
    }

    // Predict.
    for (std::size_t j = 2; j < count; ++j) {
      Vec3 a = gravity;
      if (windy) a += kWindDrag * (wind - s.v[j]);
      s.v[j] = decay * s.v[j] + dt * a;
      s.prev_x[j] = x[j];
      x[j] += dt * s.v[j];
    }
    for (std::size_t j = 1; j < count; ++j) {
      s.omega[j] *= decay;
      s.prev_q[j] = q[j];
      q[j] = spin(q[j], s.omega[j] * dt);
    }

    for (int it = 0; it < p.iterations; ++it) {
      // Shape matching over each particle's neighbourhood {c-1, c, c+1} (Jacobi: averaged).
      // E_j = R(q_j) R(q̄_j)ᵀ = R(q_j q̄_j⁻¹); that quaternion also warm-starts group j's fit.
      for (std::size_t j = 0; j < count; ++j) {
        w.orientation_quats[j] = q[j] * w.q_rest_conjugate[j];
        w.orientation_terms[j] = rotation_matrix(w.orientation_quats[j]);
      }
      for (std::size_t j = 0; j < count; ++j) w.displacement[j].setZero();
      for (std::size_t c = 1; c < count; ++c) {
        const std::size_t lo = c - 1;
        const std::size_t members = c + 1 < count ? 3 : 2;
        const Real* gw = &w.group_weights[3 * c];
        const Real* ge = &w.group_ellipsoid[3 * c];
        const Vec3* rest = &w.group_rest[3 * c];
        const Vec3* weighted_rest = &w.group_weighted_rest[3 * c];
        // A = Σ w_i (x_i - c)(x̄_i - c̄)ᵀ + e Σ w_i E_i: the ellipsoid term of Müller & Chentanez
        // 2011 (e = a²/5) with each particle's orientation defines twist even on a chain.
        const Mat3* E = &w.orientation_terms[lo];
        Vec3 centroid = gw[0] * x[lo] + gw[1] * x[lo + 1];
        Mat3 A = x[lo] * weighted_rest[0].transpose() + x[lo + 1] * weighted_rest[1].transpose();
        Mat3 orientations;
        if (lo >= 2) {
          orientations = E[0] + E[1];  // dynamic particles all weigh 1
        } else {
          orientations = ge[0] * E[0] + ge[1] * E[1];
        }
        if (members == 3) {
          centroid += gw[2] * x[lo + 2];
          A += x[lo + 2] * weighted_rest[2].transpose();
          if (lo >= 2) {
            orientations += E[2];
          } else {
            orientations += ge[2] * E[2];
          }
        }
        A += lo >= 2 ? Mat3(ellipsoid * orientations) : orientations;
        // Rotational part of A: one warm-started step of Müller et al. 2016 (see extract_rotation),
        // from the guess q_c q̄_c⁻¹ whose matrix E_c is already at hand.
        const Mat3& G = w.orientation_terms[c];
        const Vec3 torque = G.col(0).cross(A.col(0)) + G.col(1).cross(A.col(1)) + G.col(2).cross(A.col(2));
        const Real denom = std::abs(G.col(0).dot(A.col(0)) + G.col(1).dot(A.col(1)) + G.col(2).dot(A.col(2))) + 1e-12;
        const Vec3 omega = torque * (Real(0.5) / denom);
        Quat R = w.orientation_quats[c];
        Mat3 Rm = G;
        if (omega.squaredNorm() >= Real(0.25e-24)) {
          R = unit(Quat(1, omega.x(), omega.y(), omega.z()) * R);
          Rm = rotation_matrix(R);
        }
        for (std::size_t i = 0; i < members; ++i) {
          const std::size_t j = lo + i;
          if (j < 2) continue;
          w.displacement[j] += Rm * rest[i] + centroid - x[j];
        }
        w.new_q[c] = R * q_rest[c];
      }
      for (std::size_t j = 2; j < count; ++j) x[j] += (stiffness * w.inverse_hits[j]) * w.displacement[j];
      for (std::size_t c = 1; c < count; ++c) {
        const Quat& target = w.new_q[c];
        // Blend towards the (sign-aligned) target; the normalisation absorbs |target| != 1.
        const Real sign = target.dot(q[c]) < 0 ? -stiffness : stiffness;
        q[c] = unit(Quat((1 - stiffness) * q[c].coeffs() + sign * target.coeffs()));
      }
      // Inextensibility: PBD distance constraints, root (kinematic) to tip.
      project_distance(x[1], x[2], 0, 1, w.lengths[0]);
      for (std::size_t k = 1; k < n; ++k) project_distance(x[k + 1], x[k + 2], 1, 1, w.lengths[k]);
      if (!colliders.empty()) {
        for (std::size_t j = 2; j < count; ++j) push_out_of_colliders(x[j], colliders, p.radius);
      }
    }
    // Exact lengths from the root; a joint pushed out of a collider is re-pulled onto
    // its bone length, a few times, so both hold on output.
    for (std::size_t k = 0; k < n; ++k) {
      Vec3& a = x[k + 1];
      Vec3& b = x[k + 2];
      for (int pass = 0; pass < 4; ++pass) {
        const Vec3 d = b - a;
        const Real len = d.norm();
        b = len > 1e-12 ? Vec3(a + d * (w.lengths[k] / len))
                        : Vec3(a + q[k + 1] * (w.lengths[k] * rod.geometry.segment_axis(k)));
        if (colliders.empty() || !push_out_of_colliders(b, colliders, p.radius)) break;
      }
    }
    for (std::size_t j = 2; j < count; ++j) s.v[j] = (x[j] - s.prev_x[j]) * inverse_dt;
    for (std::size_t j = 1; j < count; ++j) s.omega[j] = angular_velocity(s.prev_q[j], q[j], dt);
  }
  s.anchor_position = anchor_end;
  s.anchor_rotation = anchor_end_rotation;
  if (steps == 0) {
    // No substep this frame: the chain still follows its root rigidly.
    const Quat delta = anchor_end_rotation * anchor_start_rotation.conjugate();
    for (std::size_t j = 0; j < count; ++j) {
      s.x[j] = anchor_end + delta * (s.x[j] - anchor_start);
      s.q[j] = (delta * s.q[j]).normalized();
    }
  }
}

void RodSystem::write_output(std::size_t r, float* rotations_out) {
  const RodDefinition& rod = rods_[r];
  RodState& s = states_[r];
  const std::size_t n = rod.bones.size();
  thread_local QuatList frames;
  bone_frames(rod.geometry, s, frames);
  for (std::size_t k = 0; k < n; ++k) {
    const Quat parent = k == 0 ? s.anchor_rotation : Quat(frames[k - 1] * rod.geometry.rest_rotations[k]);
    Quat basis = (parent.conjugate() * frames[k]).normalized();
    // Keep the sign continuous from frame to frame so baked F-curves interpolate.
    if (basis.dot(s.last_output[k]) < 0) basis.coeffs() = -basis.coeffs();
    s.last_output[k] = basis;
    float* out = rotations_out + 4 * static_cast<std::size_t>(rod.bones[k]);
    out[0] = static_cast<float>(basis.w());
    out[1] = static_cast<float>(basis.x());
    out[2] = static_cast<float>(basis.y());
    out[3] = static_cast<float>(basis.z());
  }
}

void RodSystem::reset(const FrameInput& input, float* rotations_out) {
  const std::vector<Collider> colliders = world_colliders(input);
  parallel_for_dynamic(rods_.size(), threads_, kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      begin_frame(r, input, colliders, true);
      if (rotations_out) write_output(r, rotations_out);
    }
  });
}

void RodSystem::step(const FrameInput& input, float* rotations_out) {
  const std::vector<Collider> colliders = world_colliders(input);
  parallel_for_dynamic(rods_.size(), threads_, kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      const bool fresh = !states_[r].initialised;
      begin_frame(r, input, colliders, fresh);
      if (!fresh) simulate(r, input, colliders);
      if (rotations_out) write_output(r, rotations_out);
    }
  });
}

Vec3List RodSystem::joint_positions(std::size_t r) const {
  const RodState& s = states_.at(r);
  if (!s.initialised) return {};
  return Vec3List(s.x.begin() + 1, s.x.end());
}

Vec3List RodSystem::joint_velocities(std::size_t r) const {
  const RodState& s = states_.at(r);
  if (!s.initialised) return {};
  return Vec3List(s.v.begin() + 1, s.v.end());
}

namespace {

// Writes into a buffer sized by state_size() (no growth checks: a frame's snapshot is
// a few megabytes at 16k bones).
struct Writer {
  Real* out;
  void put(Real v) { *out++ = v; }
  void put(const Vec3& v) { out[0] = v.x(); out[1] = v.y(); out[2] = v.z(); out += 3; }
  void put(const Quat& q) { out[0] = q.w(); out[1] = q.x(); out[2] = q.y(); out[3] = q.z(); out += 4; }
};

struct Reader {
  const Real* in;
  Real real() { return *in++; }
  Vec3 vec() { const Vec3 v(in[0], in[1], in[2]); in += 3; return v; }
  Quat quat() { const Quat q(in[0], in[1], in[2], in[3]); in += 4; return q; }
};

}  // namespace

std::size_t RodSystem::rod_state_size(std::size_t r) const {
  const std::size_t n = rods_[r].bones.size();
  return 1 + (n + 2) * (3 + 3 + 4 + 3) + n * 4 + 3 + 4 + 3 + 2 + weights_[r].size();
}

std::size_t RodSystem::state_size() const {
  std::size_t size = 0;
  for (std::size_t r = 0; r < rods_.size(); ++r) size += rod_state_size(r);
  return size;
}

void RodSystem::write_rod_state(std::size_t r, Real* out) const {
  Writer w{out};
  const RodState& s = states_[r];
  const std::size_t n = rods_[r].bones.size();
  w.put(s.initialised ? 1.0 : 0.0);
  for (std::size_t j = 0; j < n + 2; ++j) {
    w.put(s.initialised ? s.x[j] : Vec3::Zero());
    w.put(s.initialised ? s.v[j] : Vec3::Zero());
    w.put(s.initialised ? s.q[j] : Quat::Identity());
    w.put(s.initialised ? s.omega[j] : Vec3::Zero());
  }
  for (std::size_t k = 0; k < n; ++k) w.put(s.initialised ? s.last_output[k] : Quat::Identity());
  w.put(s.anchor_position);
  w.put(s.anchor_rotation);
  w.put(s.reference_position);
  w.put(s.time_accumulator);
  w.put(s.speed);
  for (Real v : weights_[r]) w.put(v);
}

void RodSystem::read_rod_state(std::size_t r, const Real* in) {
  Reader rd{in};
  RodState& s = states_[r];
  const std::size_t n = rods_[r].bones.size();
  s.initialised = rd.real() != 0;
  s.x.resize(n + 2);
  s.v.resize(n + 2);
  s.q.resize(n + 2);
  s.omega.resize(n + 2);
  s.prev_x.resize(n + 2);
  s.prev_q.resize(n + 2);
  s.rest_local.assign(n, Quat::Identity());
  s.last_output.resize(n);
  for (std::size_t j = 0; j < n + 2; ++j) {
    s.x[j] = rd.vec();
    s.v[j] = rd.vec();
    s.q[j] = rd.quat();
    s.omega[j] = rd.vec();
  }
  for (std::size_t k = 0; k < n; ++k) s.last_output[k] = rd.quat();
  s.anchor_position = rd.vec();
  s.anchor_rotation = rd.quat();
  s.reference_position = rd.vec();
  s.time_accumulator = rd.real();
  s.speed = rd.real();
  for (Real& v : weights_[r]) v = rd.real();
  // The rest shape is not stored: it is always the blend of the keys with these weights
  // (begin_frame), recomputed here bit for bit by the same function.
  if (s.initialised) {
    std::vector<const QuatList*> shapes;
    for (const RodKey& key : rods_[r].keys) shapes.push_back(&key.shape);
    blend_shapes_into(shapes.data(), shapes.size(), weights_[r].data(), n, s.rest_local);
  }
}

void RodSystem::write_state(Real* out) const {
  // Rod by rod in parallel: at 16k bones a snapshot is megabytes of fresh memory, and
  // touching it from every thread halves the page-fault time.
  std::vector<std::size_t> offsets(rods_.size() + 1, 0);
  for (std::size_t r = 0; r < rods_.size(); ++r) offsets[r + 1] = offsets[r] + rod_state_size(r);
  parallel_for_dynamic(rods_.size(), threads_, 4 * kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) write_rod_state(r, out + offsets[r]);
  });
}

void RodSystem::read_state(const Real* in) {
  for (std::size_t r = 0; r < rods_.size(); ++r) {
    read_rod_state(r, in);
    in += rod_state_size(r);
  }
}

std::vector<Real> RodSystem::save_state() const {
  std::vector<Real> out(state_size());
  write_state(out.data());
  return out;
}

void RodSystem::load_state(const std::vector<Real>& state) {
  if (state.size() != state_size()) {
    throw std::invalid_argument("state has " + std::to_string(state.size()) + " values, this system needs " +
                                std::to_string(state_size()));
  }
  read_state(state.data());
}

std::size_t RodSystem::rod_bone_count() const {
  std::size_t count = 0;
  for (const RodDefinition& rod : rods_) count += rod.bones.size();
  return count;
}

void RodSystem::store_frame(int frame, const float* rotations) {
  FrameCache::Entry entry;
  entry.state_size = state_size();
  entry.state.reset(new Real[entry.state_size]);  // not zeroed: write_state fills every value
  write_state(entry.state.get());
  entry.rotations.resize(4 * rod_bone_count());
  float* out = entry.rotations.data();
  for (const RodDefinition& rod : rods_) {
    for (int bone : rod.bones) {
      std::copy_n(rotations + 4 * static_cast<std::size_t>(bone), 4, out);
      out += 4;
    }
  }
  cache_.store(frame, std::move(entry));
}

bool RodSystem::recall_frame(int frame, float* rotations_out, bool load) {
  const FrameCache::Entry* entry = cache_.find(frame);
  if (entry == nullptr) return false;
  if (load) read_state(entry->state.get());
  if (rotations_out != nullptr) {
    const float* in = entry->rotations.data();
    for (const RodDefinition& rod : rods_) {
      for (int bone : rod.bones) {
        std::copy_n(in, 4, rotations_out + 4 * static_cast<std::size_t>(bone));
        in += 4;
      }
    }
  }
  return true;
}

}  // namespace kodawari::rod
