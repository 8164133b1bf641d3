// RodStepAhead: a RodSystem's next frame stepped on a worker thread (rod_step_ahead.hpp).
#include "kodawari/rod/rod_step_ahead.hpp"

#include <algorithm>
#include <cmath>

#include "kodawari/parallel.hpp"
#include "kodawari/worker_pool.hpp"
#include "rod_detail.hpp"

namespace kodawari::rod {

void RodStepAhead::wait() {
  if (worker_.joinable()) worker_.join();
}

bool RodStepAhead::same_state(const RodSystem& system) const {
  return source_ == &system && system.state_revision() == state_ && system.definition_revision() == definition_;
}

std::size_t RodStepAhead::drain() {
  const std::size_t rods = twin_->rod_count();
  std::size_t taken = 0;
  for (std::size_t c = next_chunk_.fetch_add(1); c < chunks_; c = next_chunk_.fetch_add(1)) {
    const std::size_t begin = c * detail::kRodsPerChunk;
    twin_->step_rods(input_, colliders_, begin, std::min(rods, begin + detail::kRodsPerChunk), rotations_.data());
    ++taken;
  }
  return taken;
}

void RodStepAhead::cancel() {
  next_chunk_.store(chunks_);  // the chunks nobody took yet are skipped: the result is dropped
  wait();
}

void RodStepAhead::start(const RodSystem& system, const FrameInput& input, const float* rotations) {
  cancel();  // an earlier step nobody finished (its frame took another path) is of no use now
  stepped_ = finite_ = false;
  chunks_ready_ = false;
  begun_ = false;
  snapshot_ = FrameCache::Entry{};
  snapshot_made_ = false;
  snapshot_wanted_ = rotations != nullptr;
  if (snapshot_wanted_) snapshot_rotations_.assign(rotations, rotations + 4 * system.bone_count());
  // A new twin is made here (rods and colliders changed: rare); the state of an existing one is
  // copied by the thread, off the caller's frame, the system pinned until it is (pin_state).
  bool copy_state = false;
  if (!twin_ || source_ != &system || definition_ != system.definition_revision()) {
    twin_ = system.twin(threads_);
    source_ = &system;
    definition_ = system.definition_revision();
  } else {
    copy_state = true;
  }
  state_ = system.state_revision();
  const std::size_t bones = system.bone_count();
  matrices_.assign(input.bone_matrices, input.bone_matrices + 16 * bones);
  rotations_.assign(4 * bones, 0.0f);
  input_ = input;
  input_.bone_matrices = matrices_.data();
  chunks_ = (twin_->rod_count() + detail::kRodsPerChunk - 1) / detail::kRodsPerChunk;
  next_chunk_ = 0;
  if (copy_state) system.pin_state();
  try {
    launch(copy_state);
  } catch (...) {  // no thread: nothing copies, nothing steps (started() stays false)
    if (copy_state) system.unpin_state();
    throw;
  }
}

void RodStepAhead::launch(bool copy_state) {
  worker_ = std::thread([this, copy_state] {
    bool copied = true;
    if (copy_state) {
      try {
        twin_->copy_state_from(*source_);  // same sizes: no allocation
      } catch (...) {  // not expected (a twin of the same rods); no result then
        copied = false;
      }
      source_->unpin_state();
    }
    try {
      if (snapshot_wanted_ && copied) {
        FrameCache::Entry entry = twin_->snapshot(snapshot_rotations_.data());
        std::lock_guard<std::mutex> lock(mutex_);
        snapshot_ = std::move(entry);
      }
    } catch (...) {  // an allocation failure: no snapshot; store() says so and the caller copies
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      snapshot_made_ = true;
    }
    made_.notify_all();
    bool ready = copied;
    try {
      if (ready) colliders_ = twin_->begin_step(input_);
    } catch (...) {  // an allocation failure: no result; the caller steps the system itself
      ready = false;
    }
    {
      std::lock_guard<std::mutex> lock(mutex_);
      chunks_ready_.store(ready, std::memory_order_release);
      begun_ = true;
    }
    made_.notify_all();
    if (!ready) {
      stepped_ = true;
      return;
    }
    // The thread and, when given more than one, the process's kept workers take the chunks.
    const unsigned drainers = static_cast<unsigned>(std::min<std::size_t>(resolve_thread_count(threads_), chunks_));
    parallel_chunks(std::max(1u, drainers), threads_, 1, [this](std::size_t, std::size_t) { drain(); });
    stepped_ = true;
  });
}

bool RodStepAhead::store(RodSystem& system, int frame) {
  if (!snapshot_wanted_ || !same_state(system)) return false;
  FrameCache::Entry entry;
  {
    std::unique_lock<std::mutex> lock(mutex_);
    made_.wait(lock, [&] { return snapshot_made_; });
    if (!snapshot_.state) return false;
    entry = std::move(snapshot_);
    snapshot_ = FrameCache::Entry{};
  }
  snapshot_wanted_ = false;  // one store per start
  system.store_snapshot(frame, std::move(entry));
  return true;
}

bool RodStepAhead::finish(float* rotations_out) {
  caller_share_ = 0.0;
  if (!worker_.joinable() && !stepped_) return false;
  // Work on the step rather than wait for it: once the thread has begun it (after the snapshot),
  // take the chunks nobody has taken yet.
  if (worker_.joinable()) {
    {
      std::unique_lock<std::mutex> lock(mutex_);
      made_.wait(lock, [&] { return begun_; });
    }
    if (chunks_ready_.load(std::memory_order_acquire)) {
      const std::size_t taken = drain();
      caller_share_ = chunks_ > 0 ? static_cast<double>(taken) / static_cast<double>(chunks_) : 0.0;
    }
  }
  wait();
  if (!stepped_ || !chunks_ready_) return false;
  finite_ = std::all_of(rotations_.begin(), rotations_.end(), [](float v) { return std::isfinite(v); });
  if (!finite_) return false;
  for (std::size_t r = 0; r < twin_->rod_count(); ++r) {
    for (int bone : twin_->rod(r).bones) {
      const std::size_t row = 4 * static_cast<std::size_t>(bone);
      std::copy_n(rotations_.data() + row, 4, rotations_out + row);
    }
  }
  return true;
}

bool RodStepAhead::adopt(RodSystem& system) {
  wait();
  if (!(stepped_ && finite_ && same_state(system))) return false;
  system.swap_state(*twin_);
  stepped_ = finite_ = false;  // the twin now holds the old state: the next start() copies afresh
  return true;
}

}  // namespace kodawari::rod
