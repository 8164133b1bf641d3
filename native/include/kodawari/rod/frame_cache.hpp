// Exact per-frame cache of a RodSystem, for scrubbing: the whole solver state of every
// simulated frame and the rod-bone rotations written that frame. Kept natively so a
// frame costs one copy in C++ instead of a state array handed to Python and back.
//
// Memory is bounded by a byte budget. Over budget, the cache thins its frames to
// checkpoints: it doubles a checkpoint interval and drops every frame that is not a
// multiple of it, except the newest frames (the ones playback and short scrubs revisit).
// A dropped frame is recomputed exactly by loading the nearest checkpoint before it and
// stepping on (the solver is deterministic), as Blender's own point caches re-simulate.
#pragma once

#include <cstddef>
#include <limits>
#include <map>
#include <memory>
#include <optional>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::rod {

class FrameCache {
 public:
  struct Entry {
    std::unique_ptr<Real[]> state;  // RodSystem::save_state()'s values (state_size of them)
    std::size_t state_size = 0;
    std::vector<float> rotations; // (rod bones, 4): every rod's bones, rod by rod, root first
    std::size_t bytes() const { return state_size * sizeof(Real) + rotations.size() * sizeof(float); }
  };

  // Frames newer than (latest - kDenseTail) are never thinned away.
  static constexpr int kDenseTail = 8;

  void store(int frame, Entry entry);
  const Entry* find(int frame) const {
    const auto it = entries_.find(frame);
    return it == entries_.end() ? nullptr : &it->second;
  }
  // The latest cached frame strictly before `frame`, if any.
  std::optional<int> latest_before(int frame) const {
    auto it = entries_.lower_bound(frame);
    if (it == entries_.begin()) return std::nullopt;
    return std::prev(it)->first;
  }
  std::vector<int> frames() const;
  void clear();

  // 0: no budget (every frame is kept).
  void set_budget(std::size_t bytes);
  std::size_t budget() const { return budget_; }
  std::size_t bytes() const { return bytes_; }
  int checkpoint_interval() const { return interval_; }
  // A state buffer to fill for the next store(): recycled from dropped frames when the
  // size matches (a 16k-bone state is megabytes: fresh pages cost more than the copy).
  std::unique_ptr<Real[]> take_buffer(std::size_t size);

 private:
  void thin();
  void recycle(Entry& entry);

  std::map<int, Entry> entries_;
  std::size_t budget_ = 0;
  std::size_t bytes_ = 0;
  int interval_ = 1;
  int clean_below_ = std::numeric_limits<int>::min();
  std::vector<std::unique_ptr<Real[]>> spare_;
  std::size_t spare_size_ = 0;
};

}  // namespace kodawari::rod
