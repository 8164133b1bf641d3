// Exact per-frame cache of a RodSystem, for scrubbing: the whole solver state of every
// simulated frame and the rod-bone rotations written that frame. Kept natively so a
// frame costs one copy in C++ instead of a state array handed to Python and back.
#pragma once

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
  };

  void store(int frame, Entry entry) { entries_[frame] = std::move(entry); }
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
  std::vector<int> frames() const {
    std::vector<int> out;
    out.reserve(entries_.size());
    for (const auto& [frame, entry] : entries_) out.push_back(frame);
    return out;
  }
  void clear() { entries_.clear(); }

 private:
  std::map<int, Entry> entries_;
};

}  // namespace kodawari::rod
