// The next frame of a RodSystem, stepped on a worker thread while the caller does other work
// (docs/algorithms.md §3.7: the hair's next frame is solved while Blender evaluates this one).
//
// start() has the system's state copied into a twin (same rods, same colliders, no cache) and the
// twin stepped by the given input on its own thread; the copy is the thread's first work (off the
// caller's frame: the system is pinned until it is made, so a change of its state meanwhile waits
// for it, RodSystem::pin_state), and the system itself is not touched, so it can be read, cached
// and stepped meanwhile. Before stepping, the thread makes the frame-cache snapshot
// of the state it started from (what system.store_frame() would make of it), which store() puts
// into the system's cache: the caller's frame is then cached without the copy. The rods are taken
// in chunks from one counter by the thread (with more than one thread, by the process's kept
// workers too) and by finish(): a caller that has to wait for the step works on it instead, so
// the core it would leave idle is not wasted. adopt() gives the system the stepped state by
// exchange, and only while the system still holds the state the step started from (its state
// revision has not moved) and its rods are the twin's. Each rod gets the arithmetic the
// system's own step() gives it, so what adopt() gives is bit for bit what step() with the same
// input would have given.
#pragma once

#include <atomic>
#include <condition_variable>
#include <cstdint>
#include <memory>
#include <mutex>
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

  // Drops an earlier step (the chunks nobody took are skipped), copies `input` (the bone matrices
  // included; the rods and colliders too when they changed) and starts the thread, which copies
  // `system`'s state first. Returns at once. With `rotations` (bone_count x 4, the rotations the
  // system's state was written with), the thread first makes the snapshot for store().
  void start(const RodSystem& system, const FrameInput& input, const float* rotations = nullptr);
  // Caches the snapshot as `frame` in `system` when it is the system the step started from and
  // still holds that state (waits for the snapshot, not for the step). False otherwise.
  bool store(RodSystem& system, int frame);
  // Steps the chunks nobody took yet, then waits for the thread. True when the step ran and
  // every rotation is finite; the rod bones' rows are then written into rotations_out
  // (bone_count x 4).
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
  void launch(bool copy_state);  // the thread: copy the state (if asked), snapshot, step
  void wait();
  void cancel();  // stops handing out chunks of a running step and waits for the thread
  bool same_state(const RodSystem& system) const;
  std::size_t drain();  // takes and steps chunks of rods until none are left; how many it took

  unsigned threads_;
  std::unique_ptr<RodSystem> twin_;
  const RodSystem* source_ = nullptr;
  std::uint64_t definition_ = 0;  // source_'s definition revision the twin was copied from
  std::uint64_t state_ = 0;       // source_'s state revision the step started from
  std::vector<float> matrices_;
  std::vector<float> rotations_;
  FrameInput input_;
  std::thread worker_;
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
