// The next frame of a RodSystem, stepped on a worker thread while the caller does other work
// (docs/algorithms.md §3.7: the hair's next frame is solved while Blender evaluates this one).
//
// start() copies the system's state into a twin (same rods, same colliders, no cache) and steps
// the twin by the given input on its own thread; the system itself is not touched, so it can be
// read, cached and stepped meanwhile. Before stepping, the thread can also make the frame-cache
// snapshot of the state it started from (what system.store_frame() would make of it), which
// store() later puts into the system's cache: the caller's frame is then cached without the copy.
// The rods are taken in chunks from one counter by the thread (and, with more than one thread,
// by the process's worker threads), and by finish() too: a caller that has to wait for the step
// works on it instead of waiting, so a core the caller leaves idle is not wasted. finish() waits and hands out the rotations; adopt() gives
// the system the stepped state by exchange, and only when the system still holds the state the
// step started from (its state revision has not moved) and its rods are the twin's. The step is
// the system's own step on an exact copy: what adopt() gives is bit for bit what the system's
// step() with the same input would have given (the rod solver's results never depend on the
// thread count, parallel.hpp).
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <mutex>
#include <memory>
#include <thread>
#include <vector>

#include "kodawari/rod/rod_system.hpp"

namespace kodawari::rod {

class RodStepAhead {
 public:
  explicit RodStepAhead(unsigned threads = 0) : threads_(threads) {}
  ~RodStepAhead() { cancel(); }
  RodStepAhead(const RodStepAhead&) = delete;
  RodStepAhead& operator=(const RodStepAhead&) = delete;

  // Drops an earlier step (its remaining chunks skipped), copies `system`'s state (its rods and colliders too when they
  // changed) and `input` (the bone matrices included), and starts the step. Returns at once.
  // With `rotations` (bone_count x 4, the rotations the system's state was written with), the
  // thread first makes the snapshot for store().
  void start(const RodSystem& system, const FrameInput& input, const float* rotations = nullptr);
  // Caches the snapshot as `frame` in `system` when it is the system the step started from and
  // still holds that state (waits for the snapshot, not for the step). False otherwise.
  bool store(RodSystem& system, int frame);
  // Waits for the step. True when it ran and every rod bone's rotation is finite; those rows
  // (rod bones only) are then written into rotations_out (bone_count x 4).
  bool finish(float* rotations_out);
  // After a successful finish(): exchanges the stepped state into `system` when it is the system
  // the step started from and still holds that state. False (nothing changes) otherwise.
  bool adopt(RodSystem& system);
  // A step is running or waits to be finished.
  bool started() const { return worker_.joinable() || stepped_; }
  // The share of the rods the last finish() stepped itself, in [0, 1]: near 0 when the thread
  // had a core to itself, near 1 when it hardly ran before it was needed.
  double caller_share() const { return caller_share_; }
  // Bones of the system the last start() copied (0 before any).
  std::size_t bone_count() const { return twin_ ? twin_->bone_count() : 0; }

 private:
  void wait();
  void cancel();  // stops handing out chunks of a running step and waits for the thread
  bool same_state(const RodSystem& system) const;

  unsigned threads_;
  std::unique_ptr<RodSystem> twin_;
  const RodSystem* source_ = nullptr;
  std::uint64_t definition_ = 0;  // source_'s definition revision the twin was copied from
  std::uint64_t state_ = 0;       // source_'s state revision the step started from
  std::vector<float> matrices_;
  std::vector<float> rotations_;
  FrameInput input_;
  std::thread worker_;
  std::size_t drain();  // takes and steps chunks of rods until none are left; how many it took
  double caller_share_ = 0.0;

  bool stepped_ = false;  // the worker ran (joined or not)
  bool finite_ = false;
  // The step's chunks: the colliders of the frame, the next chunk to take, and whether the
  // chunks may be taken (set once begin_step ran; false when the thread could not start it).
  std::vector<Collider> colliders_;
  std::atomic<std::size_t> next_chunk_{0};
  std::atomic<bool> chunks_ready_{false};
  bool begun_ = false;  // the thread got past begin_step (guarded by mutex_)
  std::size_t chunks_ = 0;
  // The snapshot for store(): the rotations it is made with, the entry, and whether it is made.
  std::vector<float> snapshot_rotations_;
  FrameCache::Entry snapshot_;
  bool snapshot_wanted_ = false;
  bool snapshot_made_ = false;  // guarded by mutex_
  std::mutex mutex_;
  std::condition_variable made_;
};

}  // namespace kodawari::rod
