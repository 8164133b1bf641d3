// The exact per-frame cache of a RodSystem (rod/frame_cache.hpp).
#include "kodawari/rod/rod_system.hpp"

#include <algorithm>


namespace kodawari::rod {

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
