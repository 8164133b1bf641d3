// Many rods, one per unbranched joint chain, simulated together: the stateful
// side of the rod solver. One call per frame takes every bone matrix of the
// armature and writes every rod bone's rotation, so Blender crosses into C++ once.
//
// Per rod and substep (oriented particles, Müller & Chentanez 2011):
//   predict x and q from v, ω, gravity, wind (GLM-noise gusts), damping;
//   `iterations` x { shape matching over each particle's neighbourhood {j-1, j, j+1},
//                   PBD distance constraints, collider push-out };
//   exact-length pass from the root, v = Δx/dt, ω from q·q_old⁻¹;
//   every 1/24 s the energy budget: no energy gained but what the root's motion brings, and a
//   chain at rest sleeps (rod_energy_budget.cpp, docs/algorithms.md §3.3).
// Particles: 0 = a kinematic "ghost" behind the root fixed in the parent's frame (it
// gives the root bone its rest direction relative to the head), 1 = the root joint
// (kinematic position, dynamic orientation), 2..n = the following joints, n+1 = the tip.
// The rest shape is re-blended from the keys every frame (view, pose, speed weights);
// with momentum control (Koyama & Igarashi 2013) a change of rest shape carries the
// chain's current deviation from rest over to the new rest shape kinematically, so a
// jump (camera cut) adds no velocity: the chain is not flung.
#pragma once

#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/rod/frame_cache.hpp"
#include "kodawari/rod/oriented_particles.hpp"
#include "kodawari/rod/shape_blend.hpp"

namespace kodawari::rod {

enum class Condition : int { View = 0, Pose = 1, Speed = 2 };

struct RodKey {
  Condition condition = Condition::View;
  Vec3 direction = Vec3::UnitY();        // VIEW: unit, in the reference bone's frame
  Quat rotation = Quat::Identity();      // POSE: the reference bone's armature-space rotation
  Real speed = 0.0;                      // SPEED: the reference bone's speed, m/s
  Real influence = 1.0;                  // p_i > 0
  QuatList shape;                        // per-bone rotations (pose-bone rotation_quaternion)
};

struct RodParams {
  Real stiffness = 0.5;     // shape-matching fraction per iteration, (0, 1]
  Real damping = 2.0;       // velocity decay rate, 1/s (docs/algorithms.md §3.3: why 2)
  Real gravity = 1.0;       // multiple of the scene's gravity
  int substeps = 4;         // substeps per 1/24 s: the substep rate is 24 * substeps Hz
  int iterations = 1;       // constraint iterations per substep
  Real radius = 0.01;       // the rod's thickness: collision margin
  Vec3 wind = Vec3::Zero(); // world-space wind velocity, m/s (gusts vary it)
  bool momentum_control = true;
};

struct RodDefinition {
  int parent_bone = -1;     // index of the kinematic parent in the armature's pose bones
  int reference_bone = -1;  // bone whose frame defines view directions
  std::vector<int> bones;   // the chain, root first
  ChainGeometry geometry;
  RodParams params;
  std::vector<RodKey> keys;
};

struct ColliderDefinition {
  int bone = -1;       // collider follows this pose bone
  bool capsule = false;
  Vec3 offset = Vec3::Zero();  // centre / axis start in the bone's frame
  Real radius = 0.1;
  Real length = 0.0;   // capsule: axis length along the bone's Y
};

// Inputs of one frame, all for the whole armature.
struct FrameInput {
  const float* bone_matrices = nullptr;  // B x 16, column-major 4x4 (pose_bones.foreach_get("matrix"))
  std::size_t bone_count = 0;
  Eigen::Matrix<Real, 4, 4> armature_matrix = Eigen::Matrix<Real, 4, 4>::Identity();  // object to world
  bool has_camera = false;
  Vec3 camera = Vec3::Zero();   // world space
  Vec3 gravity = Vec3(0, 0, -9.81);  // world space
  Real time = 0.0;              // seconds (frame / fps): drives wind gusts
  Real frame_dt = 1.0 / 24.0;   // seconds since the previous frame
};

// The energy budget's current window of 1/24 s of simulated time (docs/algorithms.md §3.3):
// the state when it opened and the moments of its motion that the budget needs. Part of the
// saved state, so a frame recalled from the cache steps on exactly as played.
struct EnergyWindow {
  int steps = -1;            // base substeps into the current 1/24 s; -1: none open
  int first = 0;             // `steps` when it opened (later than 0 after a change of rest shape)
  bool reopen = false;       // the rest shape changed: open again on the state now, same phase
  Vec3 origin = Vec3::Zero();          // the root's pose when it opened
  Quat rotation = Quat::Identity();
  Vec3List x;                // particles when it opened
  QuatList q;
  Real speed2 = 0;           // Σ |v_j|² (dynamic joints)
  Vec3 momentum = Vec3::Zero();  // Σ v_j
  Vec3 angular = Vec3::Zero();   // Σ (x_j - origin) × v_j
  Real spin2 = 0;            // Σ |ω_j|² (every particle but the ghost)
  Vec3 spin = Vec3::Zero();      // Σ ω_j
  Real shape = 0;            // the shape-matching energy
  // The last window ended by putting the state back where it began, the root still: the chain
  // rests where its energy allows and stepping it again would only repeat that. Asleep, the
  // substeps are skipped while the root stays put, gravity is unchanged and no collider
  // reaches a joint (as rigid-body engines put resting bodies to sleep).
  bool asleep = false;
  Vec3 gravity = Vec3::Zero();   // when the window opened (armature space, with the rod's factor)
};

struct RodState {
  Vec3List x, v, prev_x;     // particles (n + 2)
  QuatList q, prev_q;
  Vec3List omega;
  QuatList rest_local;       // rest shape used last frame (for momentum control)
  QuatList last_output;      // last basis written per bone (keeps quaternion signs continuous)
  Vec3 anchor_position = Vec3::Zero();
  Quat anchor_rotation = Quat::Identity();
  Vec3 reference_position = Vec3::Zero();  // world, for the speed condition
  Real time_accumulator = 0.0;
  Real speed = 0.0;
  EnergyWindow window;
  bool initialised = false;
};

// A rod's mechanical energy per unit particle mass (docs/algorithms.md §3.3): what the solver
// must never add to without input motion.
struct RodEnergy {
  Real kinetic = 0;         // ½ Σ |v_j|² + ½ Σ I |ω_j|² (I = 2e, the particles' inertia)
  Real gravitational = 0;   // -Σ g · x_j
  Real shape_matching = 0;  // (κ / 3) Σ_c min_R [½ Σ w_i |R r̄_i + c - x_i|² + ½ e Σ w_i |R - E_i|²]
  Real total() const { return kinetic + gravitational + shape_matching; }
};

class RodSystem {
 public:
  explicit RodSystem(std::size_t bone_count, unsigned threads = 0);
  ~RodSystem();  // waits for a copy of its state in flight (pin_state)
  RodSystem(RodSystem&&) noexcept = default;
  RodSystem& operator=(RodSystem&&) noexcept = default;

  // Validates and adds a rod; returns its index. Throws std::invalid_argument.
  std::size_t add_rod(RodDefinition rod);
  void set_colliders(std::vector<ColliderDefinition> colliders);

  // Puts every rod into its rest shape for the current condition, at rest.
  void reset(const FrameInput& input, float* rotations_out);
  // Advances one frame (frame_dt seconds) and writes each rod bone's rotation
  // (w, x, y, z) into rotations_out (B x 4); other rows are left untouched.
  void step(const FrameInput& input, float* rotations_out);
  // step() in parts, for a caller that hands the rods to threads of its own (RodStepAhead):
  // begin_step() once, then step_rods() over disjoint ranges covering [0, rod_count()), from
  // any threads. Each rod gets the arithmetic step() gives it.
  std::vector<Collider> begin_step(const FrameInput& input);
  void step_rods(const FrameInput& input, const std::vector<Collider>& colliders, std::size_t begin, std::size_t end,
                 float* rotations_out);

  std::size_t rod_count() const { return rods_.size(); }
  std::size_t bone_count() const { return bone_count_; }
  const RodDefinition& rod(std::size_t i) const { return rods_[i]; }
  // Joint positions (heads and tip, n + 1) in armature space.
  Vec3List joint_positions(std::size_t rod) const;
  Vec3List joint_velocities(std::size_t rod) const;
  const std::vector<Real>& weights(std::size_t rod) const { return weights_[rod]; }
  // The rod's energy now, under `gravity` (armature space, before the rod's gravity factor).
  RodEnergy energy(std::size_t rod, const Vec3& gravity) const;
  Real reference_speed(std::size_t rod) const { return states_[rod].speed; }
  // The rest shape blended this frame (per-bone rotations).
  const QuatList& rest_shape(std::size_t rod) const { return states_[rod].rest_local; }

  // The whole simulation state as doubles, for exact per-frame caching.
  std::vector<Real> save_state() const;
  void load_state(const std::vector<Real>& state);
  std::size_t state_size() const;

  // Exact per-frame cache: store_frame() snapshots the state and the rod bones' rows of
  // `rotations` (B x 4, as written by step/reset); recall_frame() loads a frame's state
  // (when load_state is true) and writes its rod-bone rows into rotations_out (if not null).
  void store_frame(int frame, const float* rotations);
  // What store_frame() caches, made now and cached later (by store_snapshot, in this system or
  // its twin: RodStepAhead makes it on its own thread).
  FrameCache::Entry snapshot(const float* rotations);
  void store_snapshot(int frame, FrameCache::Entry entry);
  bool recall_frame(int frame, float* rotations_out, bool load_state);
  FrameCache& frame_cache() { return cache_; }
  const FrameCache& frame_cache() const { return cache_; }
  // Number of rod bones (rows of a cached frame's rotations).
  std::size_t rod_bone_count() const;

  // Counters of change, for RodStepAhead (rod_step_ahead.hpp): the state revision moves with
  // every change of the simulation state (reset, step, a loaded or recalled state, an exchange),
  // the definition revision with every change of the rods or colliders.
  std::uint64_t state_revision() const { return state_revision_; }
  std::uint64_t definition_revision() const { return definition_revision_; }
  // A system with the same rods, colliders and state, without cached frames (a copy, not
  // re-added rods: add_rod normalises, and a twin must step bit for bit as this system does).
  std::unique_ptr<RodSystem> twin(unsigned threads) const;
  // The simulation state of a twin copied into this system, or exchanged with it (no copy).
  void copy_state_from(const RodSystem& twin);
  void swap_state(RodSystem& twin);
  // A copy of this state made on another thread (RodStepAhead copies it into its twin there, off
  // the caller's frame): pin_state() before handing the copy over, unpin_state() by the thread
  // once copied. Meanwhile const reads go on; every change of state (anything that moves the
  // state revision, and a change of rods or colliders) waits for the copy to end.
  void pin_state() const;
  void unpin_state() const;

 private:
  void settle() const;  // waits until no pinned copy is in flight
  void begin_frame(std::size_t r, const FrameInput& input, const std::vector<Collider>& colliders, bool reset);
  void simulate(std::size_t r, const FrameInput& input, const std::vector<Collider>& colliders);
  void write_output(std::size_t r, float* rotations_out);
  std::size_t rod_state_size(std::size_t r) const;
  void write_rod_state(std::size_t r, Real* out) const;
  void read_rod_state(std::size_t r, const Real* in);
  void write_state(Real* out) const;  // state_size() values
  void read_state(const Real* in);
  std::vector<Collider> world_colliders(const FrameInput& input) const;

  std::size_t bone_count_;
  unsigned threads_;
  std::vector<RodDefinition> rods_;
  std::vector<RodState> states_;
  std::vector<std::vector<Real>> weights_;
  std::vector<ColliderDefinition> colliders_;
  FrameCache cache_;
  std::uint64_t state_revision_ = 0;
  std::uint64_t definition_revision_ = 0;
  struct StatePin {
    std::mutex mutex;
    std::condition_variable released;
    int copies = 0;
  };
  std::unique_ptr<StatePin> pin_ = std::make_unique<StatePin>();  // unique_ptr: the system stays movable
};

// Matrix of pose bone `index` from the foreach_get buffer, with rotation and position.
void bone_transform(const float* bone_matrices, std::size_t index, Quat& rotation, Vec3& position,
                    Eigen::Matrix<Real, 3, 3>* linear = nullptr);

}  // namespace kodawari::rod
