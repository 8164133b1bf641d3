// The leg IK over a whole bake: each leg runs through the frames in order, each solve
// warm-started from the frame before (seed 3.2); a swing is solved as a whole, so a
// swinging hoof follows its path without jumps at any frame rate.
#include <limits>

#include "bake_stages.hpp"
#include "kodawari/parallel.hpp"

namespace kodawari::gait::stages {

namespace {

constexpr Real kIkTolerance = 2e-4;       // m: a planted foot is solved to a fifth of a millimetre
constexpr Real kSwingIkTolerance = 1e-3;  // m: a swinging foot, to a millimetre
// A swing the leg cannot follow within this (m) is solved again (LegIk::solve_swing).
constexpr Real kSwingTolerance = 0.01;
// Shares of the gait's swing lift tried, in order, for a swing the leg cannot follow.
constexpr Real kLiftScales[] = {1.0, 0.75, 0.5, 0.25, 0.0};

struct LegIkState {
  Real angles[kMaxBones] = {};
  Real previous[kMaxBones] = {};  // the pose one frame before `angles`
  Vec2d last_target = Vec2d(std::numeric_limits<Real>::quiet_NaN(), 0);
  Real last_error = 0;
};

struct SwingTrack {  // one way of solving a swing: a pose and a miss per frame
  std::vector<Real> angles, error;
  Real worst = std::numeric_limits<Real>::infinity();
};

// One leg through every frame.
class LegIk {
 public:
  LegIk(const BakeInput& in, const LegGeometry& legs, const Footfalls& feet, const BodyPoses& poses, int leg,
        BakeOutput& out)
      : in_(in), feet_(feet), poses_(poses), chain_(legs.chains[leg]), n_(chain_.size()), leg_(leg),
        offset_(legs.bone_offset[leg]), out_(out) {}

  void run() {
    const int frames = static_cast<int>(in_.target_speed.size());
    for (int b = 0; b < n_; ++b) state_.angles[b] = std::clamp(Real(0), chain_.limit_min[b], chain_.limit_max[b]);
    for (int f = 0; f < frames;) {
      if (feet_.contact[f * kLegCount + leg_] > 0) {
        const Vec3& goal = feet_.planned[f * kLegCount + leg_];
        record(f, goal, state_.angles, advance(state_, local_goal(f, goal), true, f < 2, nullptr));
        ++f;
        continue;
      }
      int g = f;
      while (g < frames && feet_.contact[g * kLegCount + leg_] == 0) ++g;
      solve_swing(f, g);
      f = g;
    }
  }

 private:
  Vec2d local_goal(int f, const Vec3& goal) const {
    const Vec3 local = poses_.rotations[f].transpose() * (goal - poses_.heads[f]) + in_.rig.body_head;  // rest space
    return Vec2d(local.dot(in_.rig.forward), local.z());
  }

  void record(int f, const Vec3& goal, const Real* angles, Real error) {
    for (int c = 0; c < 3; ++c) out_.feet_planned[(f * kLegCount + leg_) * 3 + c] = goal[c];
    out_.ik_error[f * 4 + leg_] = error;
    std::copy(angles, angles + n_, out_.angles.begin() + static_cast<std::ptrdiff_t>(f) * out_.bones + offset_);
  }

  // One frame on from `st` for the foot at `goal2`; returns the miss. The warm start
  // is the previous frame's pose (seed 3.2) carried on by its change from the frame
  // before (a foot's angles move smoothly, so this lands close), or `seed` if given.
  Real advance(LegIkState& st, const Vec2d& goal2, bool planted, bool first_frames, const Real* seed) const {
    Real* angles = st.angles;
    if (goal2 == st.last_target) {  // nothing moved (standing): keep the pose exactly
      std::copy(angles, angles + n_, st.previous);
      return st.last_error;
    }
    st.last_target = goal2;
    for (int bone = 0; bone < n_; ++bone) {
      const Real last = angles[bone];
      angles[bone] = seed ? seed[bone] : first_frames ? last : last + (last - st.previous[bone]);
      st.previous[bone] = last;
    }
    const Real tolerance = planted ? kIkTolerance : kSwingIkTolerance;
    st.last_error = solve_ccd(chain_, goal2, in_.ccd_iterations, tolerance, angles, planted).error;
    if (!planted && !seed && !first_frames && st.last_error > kSwingTolerance) {
      // At lift-off the foot turns back on its root: carried on, the warm start can
      // overshoot into a limit the solve cannot leave. The plain previous pose then.
      Real plain[kMaxBones];
      std::copy(st.previous, st.previous + n_, plain);
      const Real error = solve_ccd(chain_, goal2, in_.ccd_iterations, tolerance, plain, false).error;
      if (error < st.last_error) {
        std::copy(plain, plain + n_, angles);
        st.last_error = error;
      }
    }
    return st.last_error;
  }

  // The swing's goals, frames [first_, first_ + count), with `scale` of its lift.
  void set_goals(Real scale) {
    for (int i = 0; i < count_; ++i) {
      const int f = first_ + i;
      goals_[i] = feet_.planned[f * kLegCount + leg_];
      goals_[i].z() -= (1 - scale) * feet_.lift[f * kLegCount + leg_];
      goals2_[i] = local_goal(f, goals_[i]);
    }
  }

  // Forward from the lift-off pose, frame by frame with the warm start.
  void forward(SwingTrack& track) const {
    track.angles.resize(static_cast<std::size_t>(count_) * n_);
    track.error.resize(count_);
    track.worst = 0;
    LegIkState st = state_;
    for (int i = 0; i < count_; ++i) {
      track.error[i] = advance(st, goals2_[i], false, first_ + i < 2, nullptr);
      track.worst = std::max(track.worst, track.error[i]);
      std::copy(st.angles, st.angles + n_, track.angles.begin() + i * n_);
    }
  }

  // Backward in time from the landing pose, frame by frame with the warm start.
  void backward(const Real* landing, SwingTrack& track) const {
    track.angles.resize(static_cast<std::size_t>(count_) * n_);
    track.error.resize(count_);
    LegIkState st;
    std::copy(landing, landing + n_, st.angles);
    std::copy(landing, landing + n_, st.previous);
    for (int i = count_ - 1; i >= 0; --i) {
      track.error[i] = advance(st, goals2_[i], false, false, nullptr);
      std::copy(st.angles, st.angles + n_, track.angles.begin() + i * n_);
    }
  }

  // Where both the forward and the backward solve follow the path, crosses from one to
  // the other, each frame re-solved from a blend of the two. False if no frame has both.
  bool cross(const SwingTrack& ahead, const SwingTrack& back, SwingTrack& crossed) const {
    int ahead_end = 0;  // frames [0, ahead_end) follow going forward
    while (ahead_end < count_ && ahead.error[ahead_end] <= kSwingTolerance) ++ahead_end;
    int back_start = count_;  // frames [back_start, count) follow going backward
    while (back_start > 0 && back.error[back_start - 1] <= kSwingTolerance) --back_start;
    if (back_start >= ahead_end) return false;
    const int w0 = back_start, w1 = ahead_end;  // crossing window [w0, w1)
    crossed = ahead;
    crossed.worst = 0;
    LegIkState cs = state_;
    for (int i = 0; i < count_; ++i) {
      Real seed[kMaxBones];
      const Real* a = ahead.angles.data() + i * n_;
      const Real* b = back.angles.data() + i * n_;
      const Real t = std::clamp(static_cast<Real>(i - w0 + 1) / (w1 - w0 + 1), Real(0), Real(1));
      const Real w = t * t * (3 - 2 * t);
      for (int bone = 0; bone < n_; ++bone) seed[bone] = a[bone] + w * (b[bone] - a[bone]);
      crossed.error[i] = advance(cs, goals2_[i], false, false, seed);
      crossed.worst = std::max(crossed.worst, crossed.error[i]);
      std::copy(cs.angles, cs.angles + n_, crossed.angles.begin() + i * n_);
    }
    return true;
  }

  // A swing, frames [first, last), solved as a whole. Where the warm start does not
  // follow the path within kSwingTolerance -- it folded into a corner of the limits it
  // cannot leave without a jump, or the lift carries the hoof past what the limits
  // allow -- the landing pose (what the planted foot's solve, restarts allowed, finds)
  // solved backwards in time gives the other branch, and the pose crosses over where
  // both follow. Failing that, the same with less lift. The first that follows wins,
  // else the one that follows best.
  void solve_swing(int first, int last) {
    const int frames = static_cast<int>(in_.target_speed.size());
    first_ = first;
    count_ = last - first;
    goals_.resize(count_);
    goals2_.resize(count_);
    set_goals(kLiftScales[0]);
    SwingTrack best;
    forward(best);
    Real best_scale = kLiftScales[0];
    if (best.worst > kSwingTolerance) {
      Real landing[kMaxBones];
      std::copy(state_.angles, state_.angles + n_, landing);
      if (last < frames) {
        solve_ccd(chain_, local_goal(last, feet_.planned[last * kLegCount + leg_]), in_.ccd_iterations, kIkTolerance,
                  landing, true);
      }
      for (Real scale : kLiftScales) {
        SwingTrack ahead = best, back, crossed;  // the full lift's forward solve is `best`
        if (scale != kLiftScales[0]) {
          set_goals(scale);
          forward(ahead);
          if (ahead.worst < best.worst) {
            best = ahead;
            best_scale = scale;
          }
          if (ahead.worst <= kSwingTolerance) break;
        }
        backward(landing, back);
        if (!cross(ahead, back, crossed)) continue;
        if (crossed.worst < best.worst) {
          best = crossed;
          best_scale = scale;
        }
        if (crossed.worst <= kSwingTolerance) break;
      }
      set_goals(best_scale);
    }
    for (int i = 0; i < count_; ++i) record(first_ + i, goals_[i], best.angles.data() + i * n_, best.error[i]);
    // Carry the warm start on from the swing's last two poses.
    std::copy(best.angles.end() - n_, best.angles.end(), state_.angles);
    if (count_ >= 2) std::copy(best.angles.end() - 2 * n_, best.angles.end() - n_, state_.previous);
    state_.last_target = goals2_[count_ - 1];
    state_.last_error = best.error[count_ - 1];
  }

  const BakeInput& in_;
  const Footfalls& feet_;
  const BodyPoses& poses_;
  const LegChain& chain_;
  const int n_, leg_, offset_;
  BakeOutput& out_;
  LegIkState state_;
  int first_ = 0, count_ = 0;  // the swing being solved
  std::vector<Vec3> goals_;
  std::vector<Vec2d> goals2_;
};

}  // namespace

void solve_legs(const BakeInput& in, const LegGeometry& legs, const Footfalls& feet, const BodyPoses& poses,
                BakeOutput& out) {
  // Legs in parallel; one thread per leg does the same arithmetic whatever the thread
  // count: deterministic.
  parallel_for(kLegCount, 0, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t leg = begin; leg < end; ++leg) LegIk(in, legs, feet, poses, static_cast<int>(leg), out).run();
  });
}

}  // namespace kodawari::gait::stages
