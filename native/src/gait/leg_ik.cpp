// The leg IK over a whole bake: each leg runs through the frames in order, each solve
// warm-started from the frame before (seed 3.2); a swing is solved as a whole, so a
// swinging hoof follows its path without jumps at any frame rate.
#include <cmath>
#include <limits>

#include "bake_stages.hpp"
#include "stance_even.hpp"
#include "kodawari/parallel.hpp"

namespace kodawari::gait::stages {

namespace {

constexpr Real kIkTolerance = 2e-4;       // m: a planted foot is solved to a fifth of a millimetre
constexpr Real kSwingIkTolerance = 1e-3;  // m: a swinging foot, to a millimetre
// A swing the leg cannot follow within this (m) is solved again (LegIk::solve_swing).
constexpr Real kSwingTolerance = 0.01;
// A stance the leg cannot hold within this (m) going forward is solved again
// (LegIk::solve_stance).
constexpr Real kStanceTolerance = 1e-3;
// A planted foot further than this (m) from its target is a visible slide: only then
// may its solve restart cold, into another leg configuration.
constexpr Real kStanceSlide = 3e-3;
// Smoothing passes over a stance whose joint turns fast in one frame (LegIk::relax).
constexpr int kRelaxPasses = 24;
// A stance relaxed between its swings stops once no joint moves more than this (rad) in
// a pass.
constexpr Real kRelaxSettled = 1e-4;
// A planted joint turning faster than this (rad/s, 1200 deg/s) is spread (LegIk::relax).
constexpr Real kSnapRate = 1200 * kPi / 180;
// Passes over the bake in which each swing meets its stances (LegIk::meet_stances): a
// short stance ties one swing's end to the next one's start.
constexpr int kMeetPasses = 2;
// The ratio to the 3x rule (LegIk::snap_ratio) the meeting aims below: under 1 by
// a margin, as the user's joint angles, read off the evaluated pose in the leg's plane,
// differ a little from the solver's hinge angles.
constexpr Real kRuleTarget = 0.9;
// The share of the swings either side of a stance re-solved with it when its joints are
// evened out (LegIk::even_out_stance).
constexpr Real kEvenSwingShare = 0.25;
// Gauss-Newton iterations that put a foot back on its goal in each round of the evening.
constexpr int kEvenIterations = 32;
// Shares of the way to an evened stance tried where all of it breaks the 3x rule.
constexpr Real kEvenBlends[] = {0.75, 0.5, 0.25};
// The norm's last exponent of the evening tried after those (16 first: the largest change).
constexpr Real kEvenRetryExponent = 8;
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
      const bool planted = feet_.contact[f * kLegCount + leg_] > 0;
      int g = f;
      while (g < frames && (feet_.contact[g * kLegCount + leg_] > 0) == planted) ++g;
      if (planted) solve_stance(f, g);
      else solve_swing(f, g);
      spans_.push_back({f, g, planted, planted ? Real(1) : swing_scale_});
      f = g;
    }
    // Every span solved: each swing meets the stances either side of it, and each stance
    // is relaxed again between its two swings (docs/algorithms.md §4.8).
    // A later pass revisits only the spans next to one the pass before changed.
    std::vector<char> changed(spans_.size(), 1), next(spans_.size());
    for (int pass = 0; pass < kMeetPasses; ++pass) {
      std::fill(next.begin(), next.end(), 0);
      for (std::size_t i = 0; i < spans_.size(); ++i) {
        bool near = false;
        for (std::size_t j = i >= 2 ? i - 2 : 0; j <= std::min(i + 2, spans_.size() - 1); ++j) near = near || changed[j];
        if (!near) continue;
        next[i] = spans_[i].planted ? smooth_stance(i) : meet_stances(i);
      }
      changed.swap(next);
    }
    // Last, a stance whose joint turns faster than kSnapRate, or that breaks the 3x rule,
    // is evened out with the swings either side of it (docs/algorithms.md §4.8, "The
    // fastest joint of a stance").
    for (std::size_t i = 0; i < spans_.size(); ++i) {
      if (spans_[i].planted) even_out_stance(i);
    }
    // Then a lift-off still breaking the rule beside a slow first swing change carries the
    // joint at fault on into the swing ("The lift-off carries on").
    for (std::size_t i = 0; i < spans_.size(); ++i) {
      if (spans_[i].planted) lift_off_carries_on(i);
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
  // A planted foot is solved tighter; only the bake's very first frames may restart
  // cold (a new leg configuration), never a stance under way.
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
    if (!first_frames && (planted || swing_dls_)) {
      // The least change from the last pose (continuous: a planted leg never takes a new
      // configuration, and stance and swing hand over without a kink); CCD only where
      // that cannot reach the foot, and a cold restart only to keep a planted foot from
      // sliding.
      Real dls[kMaxBones];
      const Real* start = seed ? seed : (!planted && dls_from_warm_) ? angles : st.previous;
      std::copy(start, start + n_, dls);
      const Real dls_error = solve_dls(chain_, goal2, 4 * in_.ccd_iterations, tolerance, dls).error;
      if (dls_error <= (planted ? kStanceTolerance : 2 * kSwingIkTolerance) || (planted && seed)) {
        std::copy(dls, dls + n_, angles);
        st.last_error = dls_error;
        return st.last_error;
      }
      if (planted) {
        // Least change again without slowing near the limits (it stalls when most joints
        // are near theirs), still continuous.
        Real hard[kMaxBones];
        std::copy(dls, dls + n_, hard);
        const Real hard_error = solve_dls(chain_, goal2, 4 * in_.ccd_iterations, tolerance, hard, false).error;
        if (hard_error <= kStanceTolerance) {
          std::copy(hard, hard + n_, angles);
          st.last_error = hard_error;
          return st.last_error;
        }
        // CCD on from there; a cold restart (a new configuration) only if the foot would
        // otherwise slide more than kStanceSlide.
        std::copy(dls, dls + n_, angles);
        st.last_error = solve_ccd(chain_, goal2, in_.ccd_iterations, tolerance, angles, false).error;
        if (st.last_error > kStanceSlide) {
          Real cold[kMaxBones];
          std::copy(dls, dls + n_, cold);
          const Real error = solve_ccd(chain_, goal2, in_.ccd_iterations, tolerance, cold, true).error;
          if (error < st.last_error) {
            std::copy(cold, cold + n_, angles);
            st.last_error = error;
          }
        }
        if (st.last_error > dls_error) {
          std::copy(dls, dls + n_, angles);
          st.last_error = dls_error;
        }
        return st.last_error;
      }
    }
    st.last_error = solve_ccd(chain_, goal2, in_.ccd_iterations, tolerance, angles, planted && first_frames).error;
    if (!seed && !first_frames && st.last_error > (planted ? kStanceTolerance : kSwingTolerance)) {
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

  struct Span {  // a stance or a swing, frames [first, last)
    int first, last;
    bool planted;
    Real scale;  // share of the swing's lift its solve follows
  };

  // This leg's joint angles as solved for `frame`.
  Real* solved_pose(int frame) const {
    return out_.angles.data() + static_cast<std::ptrdiff_t>(frame) * out_.bones + offset_;
  }

  // The span's frames as they are solved now (the solve any other must beat), with the
  // span's goals set for `scale` of its lift.
  SwingTrack track_as_solved(const Span& span, Real scale) {
    first_ = span.first;
    count_ = span.last - span.first;
    goals_.resize(count_);
    goals2_.resize(count_);
    set_goals(scale);
    SwingTrack track;
    track.angles.resize(static_cast<std::size_t>(count_) * n_);
    track.error.resize(count_);
    track.worst = 0;
    for (int k = 0; k < count_; ++k) {
      std::copy(solved_pose(first_ + k), solved_pose(first_ + k) + n_, track.angles.begin() + k * n_);
      track.error[k] = out_.ik_error[(first_ + k) * 4 + leg_];
      track.worst = std::max(track.worst, track.error[k]);
    }
    return track;
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

  // Forward from the span's first pose (lift-off or touch-down), frame by frame with
  // the warm start.
  void forward(SwingTrack& track, bool planted = false) {
    track.angles.resize(static_cast<std::size_t>(count_) * n_);
    track.error.resize(count_);
    track.worst = 0;
    LegIkState st = state_;
    for (int i = 0; i < count_; ++i) {
      track.error[i] = advance(st, goals2_[i], planted, first_ + i < 2, nullptr);
      track.worst = std::max(track.worst, track.error[i]);
      std::copy(st.angles, st.angles + n_, track.angles.begin() + i * n_);
    }
  }

  // Backward in time from the span's last pose, frame by frame with the warm start.
  void backward(const Real* landing, SwingTrack& track, bool planted = false) const {
    track.angles.resize(static_cast<std::size_t>(count_) * n_);
    track.error.resize(count_);
    LegIkState st;
    std::copy(landing, landing + n_, st.angles);
    std::copy(landing, landing + n_, st.previous);
    for (int i = count_ - 1; i >= 0; --i) {
      track.error[i] = advance(st, goals2_[i], planted, false, nullptr);
      std::copy(st.angles, st.angles + n_, track.angles.begin() + i * n_);
    }
  }

  // Where both the forward and the backward solve follow the path, crosses from one to
  // the other, each frame re-solved from a blend of the two. False if no frame has both.
  // With `whole`, the crossing spreads over the whole span (a stance's change of
  // configuration over every planted frame instead of the few where both hold).
  bool cross(const SwingTrack& ahead, const SwingTrack& back, SwingTrack& crossed, bool planted = false,
             bool whole = false) const {
    const Real follows = planted ? kStanceTolerance : kSwingTolerance;
    int ahead_end = 0;  // frames [0, ahead_end) follow going forward
    while (ahead_end < count_ && ahead.error[ahead_end] <= follows) ++ahead_end;
    int back_start = count_;  // frames [back_start, count) follow going backward
    while (back_start > 0 && back.error[back_start - 1] <= follows) --back_start;
    if (!whole && back_start >= ahead_end) return false;
    const int w0 = whole ? -1 : back_start, w1 = whole ? count_ : ahead_end;  // crossing window [w0, w1)
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
      if (planted && (w <= 0 || w >= 1)) {
        // Outside the crossing a stance keeps the solve it crosses from or to as it is.
        const SwingTrack& from = w <= 0 ? ahead : back;
        std::copy(cs.angles, cs.angles + n_, cs.previous);
        std::copy(from.angles.begin() + i * n_, from.angles.begin() + (i + 1) * n_, cs.angles);
        cs.last_target = goals2_[i];
        cs.last_error = crossed.error[i] = from.error[i];
      } else {
        crossed.error[i] = advance(cs, goals2_[i], planted, false, seed);
      }
      crossed.worst = std::max(crossed.worst, crossed.error[i]);
      std::copy(cs.angles, cs.angles + n_, crossed.angles.begin() + i * n_);
    }
    return true;
  }

  // A stance, frames [first, last), solved as a whole like a swing: forward from the
  // touch-down pose with the warm start and no cold restart, so the leg keeps its
  // configuration while the foot is planted. Where that cannot hold the foot within
  // kStanceTolerance, the lift-off pose (solved with restarts) solved backwards in time
  // gives the other branch, and the pose crosses over, blended, where both hold it;
  // the better of the two wins.
  void solve_stance(int first, int last) {
    first_ = first;
    count_ = last - first;
    goals_.resize(count_);
    goals2_.resize(count_);
    set_goals(1);
    SwingTrack best;
    forward(best, true);
    if ((best.worst > kStanceTolerance || snaps(best)) && first_ + count_ > 2) {
      Real lift_off[kMaxBones];
      std::copy(best.angles.end() - n_, best.angles.end(), lift_off);
      solve_ccd(chain_, goals2_[count_ - 1], in_.ccd_iterations, kIkTolerance, lift_off, true);
      SwingTrack back, crossed, spread;
      backward(lift_off, back, true);
      if (cross(best, back, crossed, true) && crossed.worst < best.worst) best = crossed;
      // Crossed over a few frames the leg can turn fast (a hoof joint swinging over to
      // the lift-off configuration); spread over the whole stance it turns slowly, and
      // wins if it holds the foot as well.
      cross(best, back, spread, true, true);
      if (spread.worst <= std::max(best.worst, kStanceTolerance) && largest_turn(spread) < largest_turn(best)) {
        best = spread;
      }
    }
    if (snaps(best)) relax(best);
    finish_span(best);
  }

  // Spreads a joint's fast turn over the frames around it: each frame re-solved, holding
  // the foot, by least change from the average of its pose and its neighbours' (a few
  // Jacobi passes of a smoothing, so a turn the configuration needs is kept, only
  // slower). The touch-down neighbour is the swing's last pose.
  void relax(SwingTrack& track) const {
    std::vector<Real> next(track.angles.size());
    for (int pass = 0; pass < kRelaxPasses; ++pass) {
      Real worst = 0;
      for (int i = 0; i < count_; ++i) {
        const Real* before = i == 0 ? state_.angles : track.angles.data() + (i - 1) * n_;
        const Real* here = track.angles.data() + i * n_;
        const Real* after = i + 1 < count_ ? here + n_ : relax_after_ ? relax_after_ : here;
        Real* pose = next.data() + i * n_;
        for (int b = 0; b < n_; ++b) pose[b] = (before[b] + 2 * here[b] + after[b]) / 4;
        const Real error = solve_dls(chain_, goals2_[i], 4 * in_.ccd_iterations, kIkTolerance, pose).error;
        if (error > std::max(track.error[i], kStanceTolerance)) {
          std::copy(here, here + n_, pose);
        } else {
          track.error[i] = error;
        }
        worst = std::max(worst, track.error[i]);
      }
      Real moved = 0;
      for (std::size_t k = 0; k < next.size(); ++k) moved = std::max(moved, std::abs(next[k] - track.angles[k]));
      track.angles.swap(next);
      track.worst = worst;
      if (relax_after_ && moved < kRelaxSettled) break;  // settled (the passes between swings)
    }
  }

  // Whether a joint of `track` turns in one frame more than 3x its neighbouring frames'
  // change (+1 deg), or faster than kSnapRate: the warm start passing near a singular
  // pose or a limit.
  bool snaps(const SwingTrack& track) const {
    for (int i = 1; i + 1 < count_; ++i) {
      const Real* a = track.angles.data() + (i - 1) * n_;
      for (int b = 0; b < n_; ++b) {
        const Real here = std::abs(a[n_ + b] - a[b]);
        const Real before = i >= 2 ? std::abs(a[b] - a[b - n_]) : Real(0);
        const Real after = i + 2 <= count_ ? std::abs(a[2 * n_ + b] - a[n_ + b]) : Real(0);
        if (here > 3 * std::max(before, after) + kPi / 180 || here > kSnapRate / in_.fps) return true;
      }
    }
    return false;
  }

  // The largest change of any joint between consecutive frames of `track`, from the
  // pose before it.
  Real largest_turn(const SwingTrack& track) const {
    Real turn = 0;
    const Real* before = state_.angles;
    for (int i = 0; i < count_; ++i) {
      const Real* now = track.angles.data() + i * n_;
      for (int b = 0; b < n_; ++b) turn = std::max(turn, std::abs(now[b] - before[b]));
      before = now;
    }
    return turn;
  }

  void finish_span(const SwingTrack& best) {
    for (int i = 0; i < count_; ++i) record(first_ + i, goals_[i], best.angles.data() + i * n_, best.error[i]);
    // Carry the warm start on from the span's last two poses.
    std::copy(best.angles.end() - n_, best.angles.end(), state_.angles);
    if (count_ >= 2) std::copy(best.angles.end() - 2 * n_, best.angles.end() - n_, state_.previous);
    state_.last_target = goals2_[count_ - 1];
    state_.last_error = best.error[count_ - 1];
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
    swing_dls_ = true;
    first_ = first;
    count_ = last - first;
    goals_.resize(count_);
    goals2_.resize(count_);
    set_goals(kLiftScales[0]);
    SwingTrack best;
    forward(best);
    if (best.worst > kSwingTolerance) {  // least change stuck on a limit: plain CCD may go round it
      SwingTrack plain;
      swing_dls_ = false;
      forward(plain);
      if (plain.worst < best.worst) best = plain;
    }
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
    swing_scale_ = best_scale;
    finish_span(best);
  }

  // The rule at a planted frame (docs/algorithms.md §4.8): the largest ratio,
  // over the joints, of the change into frame `into` to 3x the larger of its
  // neighbouring changes + 1 deg, from the recorded poses (every frame solved). The first
  // joint counts the body's pitch too, as the user reads it off the evaluated pose.
  Real snap_ratio(int into) const {
    const int frames = static_cast<int>(in_.target_speed.size());
    if (into < 1 || into >= frames) return 0;
    auto step = [&](int frame, int b) {  // change from frame - 1 to frame, as the user reads it
      if (frame < 1 || frame >= frames) return Real(0);
      const Real turn = solved_pose(frame)[b] - solved_pose(frame - 1)[b];
      return std::abs(b == 0 ? turn - (pitch(frame) - pitch(frame - 1)) : turn);
    };
    Real worst = 0;
    for (int b = 0; b < n_; ++b) {
      worst = std::max(worst, step(into, b) / (3 * std::max(step(into - 1, b), step(into + 1, b)) + kPi / 180));
    }
    return worst;
  }
  // The body's pitch at `frame` (rad, nose up positive): the first joint's angle as the
  // user reads it off the evaluated pose, from straight down, turns with it.
  Real pitch(int frame) const {
    const Vec3 ahead = poses_.rotations[frame] * in_.rig.forward;
    return std::atan2(ahead.z(), std::hypot(ahead.x(), ahead.y()));
  }

  // The worst ratio to the 3x rule at the planted frames of [from, to] (within the bake).
  Real planted_rule(int from, int to) const {
    const int frames = static_cast<int>(in_.target_speed.size());
    Real worst = 0;
    for (int f = std::max(1, from); f <= std::min(frames - 1, to); ++f) {
      if (feet_.contact[f * kLegCount + leg_] > 0) worst = std::max(worst, snap_ratio(f));
    }
    return worst;
  }

  // At the touch-down of the stance [f, g): the change into it and its first change.
  Real touchdown_ratio(int f, int g) const { return std::max(snap_ratio(f), f + 1 < g ? snap_ratio(f + 1) : 0); }
  // At the lift-off of the stance [a, b): its last two changes.
  Real liftoff_ratio(int a, int b) const { return std::max(snap_ratio(b - 1), b - 2 >= a ? snap_ratio(b - 2) : 0); }

  // The swing spans_[i] and the stances either side of it (docs/algorithms.md §4.8,
  // "The swing meets its stance"): where the previous stance's lift-off or the next
  // one's touch-down breaks the rule, other solves of the swing are tried --
  // forward from lift-off carrying on the stance's joint motion (least change from the
  // warm start), backward from touch-down carrying the next stance's motion back in
  // time, and crossings from the forward solve and the old swing to the backward one
  // (over the whole swing, or where both follow the path) -- tried in that order until
  // one brings both ends within kRuleTarget, else the one with the lowest ratio there
  // is kept; a solve counts only if it follows the swing's path as well and meets the
  // stance with no larger change than before. The hoof's path stays as planned: only
  // the leg's configuration in the air changes.
  bool meet_stances(std::size_t i) {
    const int frames = static_cast<int>(in_.target_speed.size());
    const Span& swing = spans_[i];
    const Span* lifted = i > 0 && spans_[i - 1].planted ? &spans_[i - 1] : nullptr;
    const Span* landed = i + 1 < spans_.size() && spans_[i + 1].planted ? &spans_[i + 1] : nullptr;
    if (swing.first < 2) return false;
    auto score = [&] {
      return std::max(lifted ? liftoff_ratio(lifted->first, lifted->last) : 0,
                      landed ? touchdown_ratio(landed->first, landed->last) : 0);
    };
    const Real before = score();
    if (before <= kRuleTarget) return false;
    SwingTrack current = track_as_solved(swing, swing.scale);
    LegIkState start;  // the lift-off pose, moving as the stance moved it
    std::copy(solved_pose(first_ - 1), solved_pose(first_ - 1) + n_, start.angles);
    std::copy(solved_pose(first_ - 2), solved_pose(first_ - 2) + n_, start.previous);
    // The touch-down change with a solve recorded may not be larger than the stance's
    // own changes (or than it was): the rule is not to be met by a larger snap.
    auto largest_step = [&](int from, int to) {  // changes into frames [from, to)
      Real turn = 0;
      for (int frame = std::max(1, from); frame < std::min(to, frames); ++frame) {
        for (int b = 0; b < n_; ++b) turn = std::max(turn, std::abs(solved_pose(frame)[b] - solved_pose(frame - 1)[b]));
      }
      return turn;
    };
    const Real landed_pace = landed ? largest_step(landed->first + 1, landed->last) : 0;
    const Real land_before = landed ? largest_step(landed->first, landed->first + 1) : 0;
    SwingTrack best = current;
    Real best_score = before;
    auto consider = [&](const SwingTrack& track) {  // true once the rule is met
      if (track.angles.empty() || track.worst > std::max(kSwingTolerance, current.worst)) return false;
      for (int k = 0; k < count_; ++k) record(first_ + k, goals_[k], track.angles.data() + k * n_, track.error[k]);
      if (landed && largest_step(landed->first, landed->first + 1) > std::max(land_before, landed_pace) + 1e-9) {
        return false;
      }
      const Real now = score();
      if (now < best_score) {
        best_score = now;
        best = track;
      }
      return best_score <= kRuleTarget;
    };
    // Tried in the order they most often win, until one meets the rule.
    swing_dls_ = true;
    dls_from_warm_ = true;
    SwingTrack ahead, back, crossed;
    state_ = start;
    forward(ahead);
    bool met = consider(ahead);
    if (!met && landed) {
      LegIkState st;
      const int td = landed->first, after = std::min(td + 1, landed->last - 1);
      std::copy(solved_pose(td), solved_pose(td) + n_, st.angles);
      std::copy(solved_pose(after), solved_pose(after) + n_, st.previous);
      back.angles.resize(static_cast<std::size_t>(count_) * n_);
      back.error.resize(count_);
      back.worst = 0;
      for (int k = count_ - 1; k >= 0; --k) {
        back.error[k] = advance(st, goals2_[k], false, false, nullptr);
        back.worst = std::max(back.worst, back.error[k]);
        std::copy(st.angles, st.angles + n_, back.angles.begin() + k * n_);
      }
      dls_from_warm_ = false;
      met = consider(back);
      // Crossings to the backward solve, over the whole swing or where both follow.
      const SwingTrack* froms[] = {&current, &ahead, &ahead, &current};
      const bool whole[] = {true, false, true, false};
      for (int c = 0; c < 4 && !met; ++c) {
        state_ = start;
        crossed = SwingTrack();
        if (cross(*froms[c], back, crossed, false, whole[c])) met = consider(crossed);
      }
    }
    dls_from_warm_ = false;
    for (int k = 0; k < count_; ++k) record(first_ + k, goals_[k], best.angles.data() + k * n_, best.error[k]);
    return best_score < before;
  }

  // The stance spans_[i] re-solved with the last kEvenSwingShare of the swing before it
  // and the first of the swing after it for the least largest joint change between
  // frames (stance_even.cpp), where a planted joint turns faster than kSnapRate or a
  // planted change (the touch-down's included) breaks the 3x rule: the swing then lands
  // in a configuration its stance carries on from, and the stance's fastest joint is
  // slowed. Kept, or else the part of the way to it that is, or else the same evened out
  // less sharply (kEvenRetryExponent), only if it breaks the 3x rule at no planted frame
  // that kept it before (a slower peak must not come as a snap beside slow frames)
  // (docs/algorithms.md §4.8, "The fastest joint of a stance").
  bool even_out_stance(std::size_t i) {
    const int frames = static_cast<int>(in_.target_speed.size());
    if (i == 0 || i + 1 >= spans_.size() || spans_[i - 1].planted || spans_[i + 1].planted) return false;
    const Span &swing = spans_[i - 1], &stance = spans_[i], &next = spans_[i + 1];
    auto largest_step = [&](int from, int to) {  // the largest change into frames [from, to)
      Real turn = 0;
      for (int f = std::max(1, from); f < to; ++f) {
        for (int b = 0; b < n_; ++b) turn = std::max(turn, std::abs(solved_pose(f)[b] - solved_pose(f - 1)[b]));
      }
      return turn;
    };
    Real worst_ratio = 0;  // to the 3x rule at its planted frames (its touch-down included)
    for (int f = stance.first; f < stance.last; ++f) worst_ratio = std::max(worst_ratio, snap_ratio(f));
    const Real turn_before = largest_step(stance.first, stance.last);
    if (turn_before <= kSnapRate / in_.fps && worst_ratio <= 1) return false;
    auto share = [](const Span& s) {
      return std::clamp(static_cast<int>(std::lround((s.last - s.first) * kEvenSwingShare)), 0, s.last - s.first - 1);
    };
    const int start = stance.first - share(swing), end = stance.last + share(next);
    if (start < 1 || end >= frames) return false;
    const int count = end - start;
    std::vector<Real> angles(static_cast<std::size_t>(count) * n_), errors(count), allowed(count);
    std::vector<Vec2d> goals(count);
    std::vector<Vec3> goals3(count);
    std::vector<char> counted(count + 1, 0);  // the changes into planted frames
    for (int k = 0; k < count; ++k) {
      const int f = start + k;
      std::copy(solved_pose(f), solved_pose(f) + n_, angles.begin() + k * n_);
      errors[k] = out_.ik_error[f * 4 + leg_];
      const bool planted = f >= stance.first && f < stance.last;
      const Real scale = f < stance.first ? swing.scale : planted ? 1 : next.scale;
      goals3[k] = feet_.planned[f * kLegCount + leg_];
      goals3[k].z() -= (1 - scale) * feet_.lift[f * kLegCount + leg_];
      goals[k] = local_goal(f, goals3[k]);
      allowed[k] = planted ? kStanceTolerance : kSwingIkTolerance;
      counted[k] = planted;
    }
    const std::vector<Real> old_angles = angles, old_errors = errors;
    if (!even_stance(chain_, goals.data(), count, solved_pose(start - 1), solved_pose(end), counted, angles, errors,
                     kIkTolerance, allowed, kEvenIterations)) {
      return false;
    }
    auto rule = [&] { return planted_rule(start - 2, end + 2); };  // at the planted frames it touches
    const Real rule_before = std::max(rule(), Real(1));
    for (int k = 0; k < count; ++k) record(start + k, goals3[k], angles.data() + k * n_, errors[k]);
    if (const Real evened = rule(); evened <= rule_before) {
      if (evened <= 1) return true;
      // Still over the rule: the lower exponent too, whichever breaks it less.
      std::vector<Real> softer = old_angles, softer_errors = old_errors;
      if (even_stance(chain_, goals.data(), count, solved_pose(start - 1), solved_pose(end), counted, softer,
                      softer_errors, kIkTolerance, allowed, kEvenIterations, kEvenRetryExponent)) {
        for (int k = 0; k < count; ++k) record(start + k, goals3[k], softer.data() + k * n_, softer_errors[k]);
        if (rule() < evened) return true;
        for (int k = 0; k < count; ++k) record(start + k, goals3[k], angles.data() + k * n_, errors[k]);
      }
      return true;
    }
    // Broken at the lift-off only beside a slow first swing change: carried on into the swing.
    if (end > stance.last && lift_off_carries_on(i) && rule() <= rule_before) return true;
    for (int k = 0; k < count; ++k) record(start + k, goals3[k], angles.data() + k * n_, errors[k]);
    for (Real w : kEvenBlends) {  // part of the way, each frame put back on its goal
      bool held = true;
      for (int k = 0; k < count && held; ++k) {
        Real pose[kMaxBones];
        for (int b = 0; b < n_; ++b) {
          const Real was = old_angles[k * n_ + b];
          pose[b] = was + w * (angles[k * n_ + b] - was);
        }
        const Real error = solve_dls(chain_, goals[k], kEvenIterations, kIkTolerance, pose).error;
        held = error <= std::max(old_errors[k], allowed[k]);
        record(start + k, goals3[k], pose, error);
      }
      if (held && rule() <= rule_before && largest_step(stance.first, stance.last) < turn_before) return true;
    }
    // Or evened out less sharply: a lower norm's exponent spreads the turn over more joints
    // and frames without driving every change to the same peak.
    angles = old_angles;
    errors = old_errors;
    if (even_stance(chain_, goals.data(), count, solved_pose(start - 1), solved_pose(end), counted, angles, errors,
                    kIkTolerance, allowed, kEvenIterations, kEvenRetryExponent)) {
      for (int k = 0; k < count; ++k) record(start + k, goals3[k], angles.data() + k * n_, errors[k]);
      if (rule() <= rule_before) return true;
    }
    for (int k = 0; k < count; ++k) record(start + k, goals3[k], old_angles.data() + k * n_, old_errors[k]);
    return false;
  }

  // The lift-off of the stance spans_[i] where its last planted change breaks the 3x rule
  // beside a slow lift-off change (a short stance's one sweep between a touch-down and a
  // lift-off where the joint turns round): the swing's first frame re-solved on its path
  // (least change, the other joints free) with each joint at fault turned on, in the
  // direction it was turning at lift-off, by what makes its last planted change
  // kRuleTarget of the rule's allowance. Kept if the worst ratio at the planted frames
  // around falls and the hoof stays on its path (docs/algorithms.md §4.8).
  bool lift_off_carries_on(std::size_t i) {
    const int frames = static_cast<int>(in_.target_speed.size());
    if (i + 1 >= spans_.size() || spans_[i + 1].planted) return false;
    const Span &stance = spans_[i], &swing = spans_[i + 1];
    const int last = stance.last - 1, lift = stance.last;
    if (last < 2 || swing.last - swing.first < 2 || lift + 1 >= frames) return false;
    const Real before = snap_ratio(last);
    if (before <= 1) return false;
    auto user = [&](int frame, int b) { return solved_pose(frame)[b] - (b == 0 ? pitch(frame) : 0); };
    LegChain held = chain_;
    bool any = false;
    Real pose[kMaxBones];
    std::copy(solved_pose(lift), solved_pose(lift) + n_, pose);
    for (int b = 0; b < n_; ++b) {
      const Real into = std::abs(user(last, b) - user(last - 1, b));
      const Real out = user(lift, b) - user(last, b);
      const Real needed = (into / kRuleTarget - kPi / 180) / 3;
      if (into <= 3 * std::max(std::abs(user(last - 1, b) - user(last - 2, b)), std::abs(out)) + kPi / 180) continue;
      if (std::abs(out) >= needed) continue;
      const Real onward = user(lift + 1, b) - user(lift, b);
      const Real sign = out != 0 ? (out > 0 ? 1 : -1) : (onward >= 0 ? 1 : -1);
      const Real target = std::clamp(solved_pose(last)[b] + (b == 0 ? pitch(lift) - pitch(last) : 0) + sign * needed,
                                     chain_.limit_min[b], chain_.limit_max[b]);
      held.limit_min[b] = held.limit_max[b] = pose[b] = target;
      any = true;
    }
    if (!any) return false;
    Vec3 goal = feet_.planned[lift * kLegCount + leg_];
    goal.z() -= (1 - swing.scale) * feet_.lift[lift * kLegCount + leg_];
    const Real error = solve_dls(held, local_goal(lift, goal), 4 * in_.ccd_iterations, kIkTolerance, pose).error;
    const Real old_error = out_.ik_error[lift * 4 + leg_];
    if (error > std::max(old_error, kSwingIkTolerance)) return false;
    auto rule = [&] { return planted_rule(stance.first, lift + 3); };
    const Real worst_before = rule();
    std::vector<Real> old_pose(solved_pose(lift), solved_pose(lift) + n_);
    record(lift, goal, pose, error);
    if (rule() < worst_before) return true;
    record(lift, goal, old_pose.data(), old_error);
    return false;
  }

  // The stance spans_[i] relaxed again with both its neighbours solved (the swing's
  // last pose before it, the next swing's first pose after it), where one of its planted
  // changes breaks the rule; kept if that lowers its worst ratio, or its ratios over
  // kRuleTarget without raising the worst, with no larger planted change and the foot
  // held as well.
  bool smooth_stance(std::size_t i) {
    const int frames = static_cast<int>(in_.target_speed.size());
    const Span& stance = spans_[i];
    if (stance.first < 2 || stance.last >= frames) return false;
    auto score = [&] {  // (the worst ratio, the sum of the ratios over 1)
      std::pair<Real, Real> s{0, 0};
      for (int into = stance.first; into < stance.last; ++into) {
        const Real r = snap_ratio(into);
        s.first = std::max(s.first, r);
        s.second += std::max(Real(0), r - kRuleTarget);
      }
      return s;
    };
    auto largest_step = [&] {
      Real turn = 0;
      for (int frame = stance.first; frame < stance.last; ++frame) {
        for (int b = 0; b < n_; ++b) turn = std::max(turn, std::abs(solved_pose(frame)[b] - solved_pose(frame - 1)[b]));
      }
      return turn;
    };
    const std::pair<Real, Real> before = score();
    if (before.first <= 1) return false;
    const Real turn_before = largest_step();
    SwingTrack current = track_as_solved(stance, 1);
    std::copy(solved_pose(first_ - 1), solved_pose(first_ - 1) + n_, state_.angles);
    std::vector<Real> after(solved_pose(stance.last), solved_pose(stance.last) + n_);
    relax_after_ = after.data();
    SwingTrack relaxed = current;
    relax(relaxed);
    relax_after_ = nullptr;
    if (relaxed.worst > std::max(current.worst, kStanceTolerance)) return false;
    for (int k = 0; k < count_; ++k) record(first_ + k, goals_[k], relaxed.angles.data() + k * n_, relaxed.error[k]);
    const std::pair<Real, Real> now = score();
    const bool better = now.first < before.first || (now.first <= before.first && now.second < before.second - 1e-9);
    if (better && largest_step() <= turn_before + 1e-9) return true;
    for (int k = 0; k < count_; ++k) record(first_ + k, goals_[k], current.angles.data() + k * n_, current.error[k]);
    return false;
  }

  const BakeInput& in_;
  const Footfalls& feet_;
  const BodyPoses& poses_;
  const LegChain& chain_;
  const int n_, leg_, offset_;
  BakeOutput& out_;
  LegIkState state_;
  int first_ = 0, count_ = 0;  // the swing being solved
  bool swing_dls_ = true;      // swings solved by least change first (CCD where that fails)
  bool dls_from_warm_ = false;  // least change from the warm start (joint motion carried on)
  const Real* relax_after_ = nullptr;  // the pose after a relaxed stance, if solved
  std::vector<Span> spans_;
  Real swing_scale_ = 1;  // of the swing solved last
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
