// RodSystem's lifecycle: validating and adding rods and colliders, reset and step
// over every rod (in parallel), and writing each bone's rotation. The rods go to the
// process's kept worker threads (worker_pool.hpp), not to threads started per call: a frame
// does not wait for a thread the machine has not scheduled yet.
#include "kodawari/rod/rod_system.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>
#include <string>

#include "kodawari/worker_pool.hpp"
#include "rod_detail.hpp"

namespace kodawari::rod {

using namespace detail;

namespace {
// Definition revisions are unique in the process, so a system built where a freed one lived
// never passes for it (RodStepAhead).
std::uint64_t next_definition_revision() {
  static std::atomic<std::uint64_t> counter{0};
  return ++counter;
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

RodSystem::~RodSystem() { settle(); }

void RodSystem::pin_state() const {
  std::lock_guard<std::mutex> lock(pin_->mutex);
  ++pin_->copies;
}

void RodSystem::unpin_state() const {
  {
    std::lock_guard<std::mutex> lock(pin_->mutex);
    --pin_->copies;
  }
  pin_->released.notify_all();
}

void RodSystem::settle() const {
  if (!pin_) return;  // moved from
  std::unique_lock<std::mutex> lock(pin_->mutex);
  pin_->released.wait(lock, [this] { return pin_->copies == 0; });
}

std::size_t RodSystem::add_rod(RodDefinition rod) {
  settle();
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
  definition_revision_ = next_definition_revision();
  ++state_revision_;
  return rods_.size() - 1;
}

void RodSystem::set_colliders(std::vector<ColliderDefinition> colliders) {
  settle();
  for (const auto& c : colliders) {
    if (c.bone < 0 || static_cast<std::size_t>(c.bone) >= bone_count_) {
      throw std::invalid_argument("a collider bone index is outside the armature");
    }
    if (!(c.radius >= 0) || !std::isfinite(c.radius) || !(c.length >= 0) || !finite(c.offset)) {
      throw std::invalid_argument("collider radius and length must be finite and >= 0");
    }
  }
  colliders_ = std::move(colliders);
  definition_revision_ = next_definition_revision();
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
  settle();
  ++state_revision_;
  const std::vector<Collider> colliders = world_colliders(input);
  parallel_chunks(rods_.size(), threads_, kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) {
      begin_frame(r, input, colliders, true);
      if (rotations_out) write_output(r, rotations_out);
    }
  });
}

std::vector<Collider> RodSystem::begin_step(const FrameInput& input) {
  settle();
  ++state_revision_;
  return world_colliders(input);
}

void RodSystem::step_rods(const FrameInput& input, const std::vector<Collider>& colliders, std::size_t begin,
                          std::size_t end, float* rotations_out) {
  for (std::size_t r = begin; r < end; ++r) {
    const bool fresh = !states_[r].initialised;
    begin_frame(r, input, colliders, fresh);
    if (!fresh) simulate(r, input, colliders);
    if (rotations_out) write_output(r, rotations_out);
  }
}

void RodSystem::step(const FrameInput& input, float* rotations_out) {
  const std::vector<Collider> colliders = begin_step(input);
  parallel_chunks(rods_.size(), threads_, kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    step_rods(input, colliders, begin, end, rotations_out);
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


std::unique_ptr<RodSystem> RodSystem::twin(unsigned threads) const {
  auto twin = std::make_unique<RodSystem>(bone_count_, threads);
  twin->rods_ = rods_;
  twin->colliders_ = colliders_;
  twin->states_ = states_;
  twin->weights_ = weights_;
  return twin;
}

void RodSystem::copy_state_from(const RodSystem& twin) {
  if (twin.rods_.size() != rods_.size() || twin.bone_count_ != bone_count_) {
    throw std::invalid_argument("copy_state_from: not a twin of this system");
  }
  settle();
  states_ = twin.states_;  // same sizes: the vectors keep their memory, no allocation
  weights_ = twin.weights_;
  ++state_revision_;
}

void RodSystem::swap_state(RodSystem& twin) {
  if (twin.rods_.size() != rods_.size() || twin.bone_count_ != bone_count_) {
    throw std::invalid_argument("swap_state: not a twin of this system");
  }
  settle();
  twin.settle();
  states_.swap(twin.states_);
  weights_.swap(twin.weights_);
  ++state_revision_;
  ++twin.state_revision_;
}

std::size_t RodSystem::rod_bone_count() const {
  std::size_t count = 0;
  for (const RodDefinition& rod : rods_) count += rod.bones.size();
  return count;
}

}  // namespace kodawari::rod
