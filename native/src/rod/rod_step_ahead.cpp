// RodStepAhead: a RodSystem's next frame stepped on a worker thread (rod_step_ahead.hpp).
#include "kodawari/rod/rod_step_ahead.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::rod {

void RodStepAhead::wait() {
  if (worker_.joinable()) worker_.join();
}

void RodStepAhead::start(const RodSystem& system, const FrameInput& input) {
  wait();
  stepped_ = finite_ = false;
  if (!twin_ || source_ != &system || definition_ != system.definition_revision()) {
    twin_ = system.twin(threads_);
    source_ = &system;
    definition_ = system.definition_revision();
  } else {
    twin_->copy_state_from(system);
  }
  state_ = system.state_revision();
  const std::size_t bones = system.bone_count();
  matrices_.assign(input.bone_matrices, input.bone_matrices + 16 * bones);
  rotations_.assign(4 * bones, 0.0f);
  input_ = input;
  input_.bone_matrices = matrices_.data();
  worker_ = std::thread([this] {
    bool finite = false;
    try {
      twin_->step(input_, rotations_.data());
      finite = std::all_of(rotations_.begin(), rotations_.end(), [](float v) { return std::isfinite(v); });
    } catch (...) {  // an allocation failure: no result; the caller steps the system itself
      finite = false;
    }
    finite_ = finite;
    stepped_ = true;
  });
}

bool RodStepAhead::finish(float* rotations_out) {
  wait();
  if (!stepped_ || !finite_) return false;
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
  const bool same = stepped_ && finite_ && source_ == &system && system.state_revision() == state_ &&
                    system.definition_revision() == definition_;
  if (!same) return false;
  system.swap_state(*twin_);
  stepped_ = finite_ = false;  // the twin now holds the old state: the next start() copies afresh
  return true;
}

}  // namespace kodawari::rod
