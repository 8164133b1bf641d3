// The exact per-frame cache of a RodSystem (rod/frame_cache.hpp).
#include "kodawari/rod/rod_system.hpp"

#include <algorithm>
#include <limits>
#include <stdexcept>

namespace kodawari::rod {

void FrameCache::store(int frame, Entry entry) {
  auto it = entries_.find(frame);
  if (it != entries_.end()) {
    bytes_ -= it->second.bytes();
    recycle(it->second);
    entries_.erase(it);
  }
  bytes_ += entry.bytes();
  entries_.emplace(frame, std::move(entry));
  thin();
}

std::vector<int> FrameCache::frames() const {
  std::vector<int> out;
  out.reserve(entries_.size());
  for (const auto& [frame, entry] : entries_) out.push_back(frame);
  return out;
}

void FrameCache::clear() {
  entries_.clear();
  bytes_ = 0;
  interval_ = 1;
  clean_below_ = std::numeric_limits<int>::min();
}

void FrameCache::set_budget(std::size_t bytes) {
  budget_ = bytes;
  thin();
}

std::unique_ptr<Real[]> FrameCache::take_buffer(std::size_t size) {
  if (!spare_.empty() && spare_size_ == size) {
    std::unique_ptr<Real[]> buffer = std::move(spare_.back());
    spare_.pop_back();
    return buffer;
  }
  return std::unique_ptr<Real[]>(new Real[size]);
}

void FrameCache::recycle(Entry& entry) {
  if (!entry.state) return;
  if (spare_.empty() || spare_size_ != entry.state_size) {
    spare_.clear();
    spare_size_ = entry.state_size;
  }
  if (spare_.size() < 2) spare_.push_back(std::move(entry.state));
}

void FrameCache::thin() {
  constexpr int kLargestInterval = 1 << 28;
  auto drop = [this](std::map<int, Entry>::iterator it) {
    bytes_ -= it->second.bytes();
    recycle(it->second);
    return entries_.erase(it);
  };
  while (budget_ > 0 && bytes_ > budget_ && entries_.size() > 1) {
    const int first = entries_.begin()->first;
    const int latest = entries_.rbegin()->first;
    // Frames below clean_below_ hold only checkpoints of this interval already: scan the rest
    // (one store usually drops the one frame that just left the dense tail).
    bool dropped = false;
    for (auto it = entries_.lower_bound(clean_below_); it != entries_.end() && it->first <= latest - kDenseTail;) {
      const int f = it->first;
      const bool checkpoint = f == first || ((f % interval_) + interval_) % interval_ == 0;
      if (checkpoint) {
        ++it;
      } else {
        it = drop(it);
        dropped = true;
      }
    }
    clean_below_ = latest - kDenseTail + 1;
    if (dropped) continue;
    if (interval_ < kLargestInterval) {
      interval_ *= 2;  // keep every other checkpoint
      clean_below_ = std::numeric_limits<int>::min();
      continue;
    }
    // Checkpoints and the newest frames alone exceed the budget: keep the newest.
    while (bytes_ > budget_ && entries_.size() > 1) drop(entries_.begin());
  }
}

FrameCache::Entry RodSystem::snapshot(const float* rotations) {
  FrameCache::Entry entry;
  entry.state_size = state_size();
  entry.state = cache_.take_buffer(entry.state_size);  // not zeroed: write_state fills every value
  write_state(entry.state.get());
  entry.rotations.resize(4 * rod_bone_count());
  float* out = entry.rotations.data();
  for (const RodDefinition& rod : rods_) {
    for (int bone : rod.bones) {
      std::copy_n(rotations + 4 * static_cast<std::size_t>(bone), 4, out);
      out += 4;
    }
  }
  return entry;
}

void RodSystem::store_frame(int frame, const float* rotations) { cache_.store(frame, snapshot(rotations)); }

void RodSystem::store_snapshot(int frame, FrameCache::Entry entry) {
  if (entry.state_size != state_size() || entry.rotations.size() != 4 * rod_bone_count()) {
    throw std::invalid_argument("store_snapshot: the snapshot is of another system");
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
