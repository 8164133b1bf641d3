// The whole solver state as doubles: save/load for exact caches and saved files.
#include "kodawari/rod/rod_system.hpp"

#include <stdexcept>
#include <string>

#include "kodawari/worker_pool.hpp"
#include "rod_detail.hpp"

namespace kodawari::rod {

using namespace detail;

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
  // The energy window: steps, origin, rotation, x and q of every particle, 11 moments and the shape energy.
  return 1 + (n + 2) * (3 + 3 + 4 + 3) + n * 4 + 3 + 4 + 3 + 2 + weights_[r].size() + 1 + 3 + 4 + (n + 2) * 7 + 11 +
         1 + 1 + 3 + 2;
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
  const EnergyWindow& window = s.window;
  const bool open = s.initialised && window.steps >= 0;
  w.put(open ? Real(window.steps) : Real(-1));
  w.put(open ? window.origin : Vec3::Zero());
  w.put(open ? window.rotation : Quat::Identity());
  for (std::size_t j = 0; j < n + 2; ++j) {
    w.put(open ? window.x[j] : Vec3::Zero());
    w.put(open ? window.q[j] : Quat::Identity());
  }
  w.put(open ? window.speed2 : Real(0));
  w.put(open ? window.momentum : Vec3::Zero());
  w.put(open ? window.angular : Vec3::Zero());
  w.put(open ? window.spin2 : Real(0));
  w.put(open ? window.spin : Vec3::Zero());
  w.put(open ? window.shape : Real(0));
  w.put(open && window.asleep ? Real(1) : Real(0));
  w.put(open ? window.gravity : Vec3::Zero());
  w.put(open ? Real(window.first) : Real(0));
  w.put(open && window.reopen ? Real(1) : Real(0));
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
  EnergyWindow& window = s.window;
  window.steps = static_cast<int>(rd.real());
  window.origin = rd.vec();
  window.rotation = rd.quat();
  window.x.resize(n + 2);
  window.q.resize(n + 2);
  for (std::size_t j = 0; j < n + 2; ++j) {
    window.x[j] = rd.vec();
    window.q[j] = rd.quat();
  }
  window.speed2 = rd.real();
  window.momentum = rd.vec();
  window.angular = rd.vec();
  window.spin2 = rd.real();
  window.spin = rd.vec();
  window.shape = rd.real();
  window.asleep = rd.real() != 0;
  window.gravity = rd.vec();
  window.first = static_cast<int>(rd.real());
  window.reopen = rd.real() != 0;
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
  parallel_chunks(rods_.size(), threads_, 4 * kRodsPerChunk, [&](std::size_t begin, std::size_t end) {
    for (std::size_t r = begin; r < end; ++r) write_rod_state(r, out + offsets[r]);
  });
}

void RodSystem::read_state(const Real* in) {
  settle();
  ++state_revision_;
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

}  // namespace kodawari::rod
