#include "kodawari/gait/planner.hpp"
#include "kodawari/gait/swing_path.hpp"

#include "kodawari/parallel.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace kodawari::gait {

namespace {

using Vec2d = Eigen::Matrix<Real, 2, 1>;

constexpr Real kSubstepRate = 480;   // planner grid, Hz: events land within ~2 ms
constexpr Real kStandSpeed = 1e-4;   // below this the clocks of planted legs pause
constexpr Real kReachMargin = 0.93;  // IK targets stay inside 93% of what the chain reaches
constexpr int kReachSamples = 64;
constexpr Real kIkTolerance = 2e-4;  // m: a planted foot is solved to a fifth of a millimetre
constexpr Real kSwingIkTolerance = 1e-3;  // m: a swinging foot, to a millimetre
constexpr int kMaxBones = 6;
// A swing the leg cannot follow within this (m) is re-planned lower (see the IK pass).
constexpr Real kSwingTolerance = 0.01;
// Shares of the gait's swing lift tried, in order, for a swing the leg cannot follow.
constexpr Real kLiftScales[] = {1.0, 0.75, 0.5, 0.25, 0.0};

Vec3 up() { return Vec3(0, 0, 1); }
Vec2d horizontal(const Vec3& v) { return Vec2d(v.x(), v.y()); }

struct Frame2 {  // body pose on the ground plane at one planner step
  Vec2d head;
  Vec2d heading;
};

struct Path {
  std::vector<Vec2d> points;
  std::vector<Real> arc;
  bool empty() const { return points.size() < 2; }
  Vec2d at(Real s) const {
    if (s <= 0) return points.front() + (points[1] - points[0]).normalized() * s;
    if (s >= arc.back()) {
      const Vec2d d = (points.back() - points[points.size() - 2]).normalized();
      return points.back() + d * (s - arc.back());
    }
    const auto it = std::upper_bound(arc.begin(), arc.end(), s);
    const std::size_t i = static_cast<std::size_t>(it - arc.begin()) - 1;
    const Real span = arc[i + 1] - arc[i];
    const Real w = span > 0 ? (s - arc[i]) / span : 0;
    return points[i] + w * (points[i + 1] - points[i]);
  }
};

Path make_path(const Vec3List& polyline) {
  Path path;
  for (const Vec3& p : polyline) {
    const Vec2d q = horizontal(p);
    if (!path.points.empty() && (q - path.points.back()).norm() < 1e-9) continue;
    path.points.push_back(q);
  }
  path.arc.assign(path.points.size(), 0);
  for (std::size_t i = 1; i < path.points.size(); ++i) {
    path.arc[i] = path.arc[i - 1] + (path.points[i] - path.points[i - 1]).norm();
  }
  return path;
}

Vec2d rotate2(const Vec2d& v, const Vec2d& from, const Vec2d& to) {
  // The rotation taking unit `from` to unit `to`, applied to v.
  const Real c = from.dot(to), s = from.x() * to.y() - from.y() * to.x();
  return Vec2d(c * v.x() - s * v.y(), s * v.x() + c * v.y());
}

struct LegPlan {
  bool stance = true;
  long lift = 0;          // planned lift-off step (stance)
  long touchdown = 0;     // touchdown step of the current stance, or planned for a swing
  long next_stance = 0;   // stance length planned for after the current swing
  long swing_start = 0, swing_length = 1;
  Vec3 foot = Vec3::Zero();   // planted foot, or swing start
  Vec3 target = Vec3::Zero();  // swing landing point
  Real swing_height = 0, swing_peak = 0.5, ease = kEaseMax;
};

struct Reach {  // how far a chain reaches in each downward direction
  std::vector<Real> table;
  Real at(Real angle) const {  // angle in [-pi, 0], CCW from +forward
    const Real x = std::clamp((angle + kPi) / kPi, Real(0), Real(1)) * (kReachSamples - 1);
    const int i = std::min(kReachSamples - 2, static_cast<int>(x));
    const Real w = x - i;
    return table[i] * (1 - w) + table[i + 1] * w;
  }
};

}  // namespace

BakeOutput bake_gait(const BakeInput& in) {
  const GaitTable& table = in.table;
  const Rig& rig = in.rig;
  const int frames = static_cast<int>(in.target_speed.size());
  BakeOutput out;
  out.frames = frames;
  if (frames == 0) return out;

  const Vec3 F = rig.forward;
  const Vec3 A = up().cross(F);  // lateral hinge axis
  const Vec2d F2 = horizontal(F);

  // --- rig -------------------------------------------------------------------
  std::array<LegChain, kLegCount> chains;
  std::array<Reach, kLegCount> reach_tables;
  std::array<Real, kLegCount> reach{}, neutral{}, lateral{}, sole{}, root_height{};
  std::array<Vec3, kLegCount> root_rel{};  // leg root relative to the body head, rest
  std::array<int, kLegCount> bone_offset{};
  Real ground_plane = std::numeric_limits<Real>::infinity();
  for (int leg = 0; leg < kLegCount; ++leg) ground_plane = std::min(ground_plane, rig.legs[leg].tail.z());
  Real leg_length = 0;
  for (int leg = 0; leg < kLegCount; ++leg) {
    chains[leg] = make_chain(rig, leg);
    bone_offset[leg] = out.bones;
    out.bones += chains[leg].size();
    const Vec3 root = rig.legs[leg].heads[0], foot = rig.legs[leg].tail;
    reach[leg] = table.reach * chains[leg].length();
    neutral[leg] = (foot - root).dot(F);
    lateral[leg] = (foot - root).dot(A);
    sole[leg] = foot.z() - ground_plane;
    root_rel[leg] = root - rig.body_head;
    root_height[leg] = root.z() - foot.z();
    reach_tables[leg].table.resize(kReachSamples);
    for (int i = 0; i < kReachSamples; ++i) {
      const Real angle = -kPi + kPi * i / (kReachSamples - 1);
      reach_tables[leg].table[i] = directional_reach(chains[leg], Vec2d(std::cos(angle), std::sin(angle)));
    }
    if (!is_fore(leg)) leg_length = std::max(leg_length, root.z() - foot.z());
  }
  out.reach.assign(reach.begin(), reach.end());
  auto ground_at = [&](const Vec2d& p) {
    return in.ground.empty() ? ground_plane : in.ground.at(p.x(), p.y());
  };

  // --- body on the ground plane: speed with the acceleration limit, gait choice ------
  const int substeps = std::max(1, static_cast<int>(std::ceil(kSubstepRate / in.fps - 1e-9)));
  const Real dt = Real(1) / (in.fps * substeps);
  const long last_step = static_cast<long>(frames - 1) * substeps;
  const long lookahead = static_cast<long>(std::ceil(3.0 / dt));  // plans look up to ~2 strides ahead
  const long steps = last_step + lookahead + 1;
  std::vector<Real> distance(steps), speed(steps);
  std::vector<int> gait(steps);
  std::vector<Frame2> body(steps);
  const Path path = make_path(in.path);
  {
    Real v = std::max(Real(0), in.target_speed[0]);
    Real s = 0;
    int current = in.gait_mode[0] >= 0 ? in.gait_mode[0] : static_cast<int>(select_gait(table, v, -1, leg_length));
    for (long k = 0; k < steps; ++k) {
      const Real frame = static_cast<Real>(k) / substeps;
      const int f0 = std::min(frames - 1, static_cast<int>(frame));
      const int f1 = std::min(frames - 1, f0 + 1);
      const Real w = std::min(Real(1), frame - f0);
      const Real target = std::max(Real(0), in.target_speed[f0] * (1 - w) + in.target_speed[f1] * w);
      if (k > 0) {
        const Real dv = std::clamp(target - v, -in.acceleration * dt, in.acceleration * dt);
        v = std::max(Real(0), v + dv);
        s += v * dt;
      }
      const int mode = in.gait_mode[f0];
      current = mode >= 0 ? mode : static_cast<int>(select_gait(table, v, current, leg_length));
      speed[k] = v;
      distance[k] = s;
      gait[k] = current;
    }
    for (long k = 0; k < steps; ++k) {
      if (path.empty()) {
        body[k].head = horizontal(rig.body_head) + F2 * distance[k];
        body[k].heading = F2;
      } else {
        body[k].head = path.at(distance[k]);
        const Vec2d d = path.at(distance[k] + 0.25) - path.at(distance[k] - 0.25);
        body[k].heading = d.norm() > 1e-9 ? Vec2d(d.normalized()) : F2;
      }
    }
  }
  auto clamp_step = [&](long k) { return std::clamp(k, 0L, steps - 1); };
  auto root_at = [&](int leg, long k) -> Vec2d {
    const Frame2& b = body[clamp_step(k)];
    return b.head + rotate2(horizontal(root_rel[leg]), F2, b.heading);
  };
  auto lateral_dir = [&](long k) -> Vec2d {
    const Vec2d h = body[clamp_step(k)].heading;
    return Vec2d(-h.y(), h.x());
  };
  auto cycle_steps = [&](long k) { return cycle_time(table.gaits[gait[clamp_step(k)]]) / dt; };
  auto duty = [&](long k) { return table.gaits[gait[clamp_step(k)]].duty_factor; };
  auto swing_margin = [&](Real v, const GaitParams& p) { return ease_lag(v, p.swing_time); };

  // --- legs: phase clocks on the planner grid --------------------------------
  std::array<LegPlan, kLegCount> plan;
  auto lh_next_lift = [&]() -> Real {
    const LegPlan& lh = plan[kLH];
    return lh.stance ? Real(lh.lift) : Real(lh.touchdown + lh.next_stance);
  };
  // Stance length for `leg` touching down at step t1: the gait's alpha T, shifted so
  // the lift-off lands on the gait's phase relative to LH (seed 3.3: "add the timing
  // difference to the current or next stance"). The shift is at most half a cycle;
  // what the reach guard cuts off is caught up on the next stride.
  auto plan_stance = [&](int leg, long t1) -> long {
    const Real T = cycle_steps(t1);
    const Real nominal = duty(t1) * T;
    Real length = nominal;
    if (leg != kLH) {
      const Real ref = lh_next_lift();
      const Real theta = leg_phase(table.gaits[gait[clamp_step(t1)]], static_cast<Gait>(gait[clamp_step(t1)]), leg);
      const Real cycles = std::round((t1 + nominal - ref - theta * T) / T);
      length = ref + (theta + cycles) * T - t1;
    }
    return std::max(std::max(1L, static_cast<long>(std::lround(0.35 * nominal))), static_cast<long>(std::lround(length)));
  };
  auto start_swing = [&](int leg, long k) {
    LegPlan& p = plan[leg];
    const GaitParams& g = table.gaits[gait[clamp_step(k)]];
    p.stance = false;
    p.swing_start = k;
    p.swing_length = std::max(1L, static_cast<long>(std::lround(g.swing_time / dt)));
    p.touchdown = k + p.swing_length;
    p.next_stance = plan_stance(leg, p.touchdown);
    {
      // At speed the reach caps how long a stance can last (2 x margin of travel). A
      // phase shift the stance cannot absorb is taken by this swing, stretched by at
      // most a half (the rest waits for the next stride).
      const Real v = std::max(speed[clamp_step(p.touchdown)], Real(1e-6));
      const Real longest = 2 * (reach[leg] - swing_margin(v, g)) / v / dt;
      const long excess = static_cast<long>(std::floor(p.next_stance - longest));
      if (excess > 0) {
        const long stretch = std::min(excess, p.swing_length / 2);
        p.swing_length += stretch;
        p.touchdown += stretch;
        p.next_stance = plan_stance(leg, p.touchdown);
      }
    }
    // Landing point (seed eq. 3.6 in closed form): the root's travel during the swing
    // plus half the next stance's travel, measured from the root at touchdown. For a
    // speed step V -> V' made C before lift-off, with t added to the stance, this is
    // S = V'P/(1-a) + (V'-V)C + V't plus the re-centring of the new stance under the
    // root, which is what keeps every foot inside its reach.
    const long td = p.touchdown;
    const Real stance_travel = distance[clamp_step(td + p.next_stance)] - distance[clamp_step(td)];
    const Real v_td = speed[clamp_step(td)];
    const Real margin = reach[leg] - swing_margin(v_td, g);
    const Real offset = neutral[leg] + std::clamp(stance_travel / 2, -margin, margin);
    const Vec2d land = root_at(leg, td) + body[clamp_step(td)].heading * offset + lateral_dir(td) * lateral[leg];
    p.target = Vec3(land.x(), land.y(), ground_at(land) + sole[leg]);
    p.swing_height = g.swing_height;
    p.swing_peak = g.swing_peak;
    p.ease = swing_ease(std::max(speed[clamp_step(k)], v_td), g.swing_time);
  };
  auto lift_at = [&](int leg, long k) -> Real {  // height of a swinging foot above its ground path
    const LegPlan& p = plan[leg];
    if (p.stance) return 0;
    return p.swing_height * swing_lift(static_cast<Real>(k - p.swing_start) / p.swing_length, p.swing_peak);
  };
  auto foot_at = [&](int leg, long k) -> Vec3 {
    const LegPlan& p = plan[leg];
    if (p.stance) return p.foot;
    const Real s = static_cast<Real>(k - p.swing_start) / p.swing_length;
    const Real w = swing_progress(s, p.ease);
    Vec3 x = p.foot + (p.target - p.foot) * w;
    x.z() += lift_at(leg, k);
    return x;
  };

  // Start planted on the rest feet, LH half-way through its stance, the others on
  // their phases after it.
  {
    const Real T = cycle_steps(0);
    const long lh_lift = std::max(1L, static_cast<long>(std::lround(0.5 * duty(0) * T)));
    for (int leg = 0; leg < kLegCount; ++leg) {
      LegPlan& p = plan[leg];
      const Vec2d foot2 = root_at(leg, 0) + body[0].heading * neutral[leg] + lateral_dir(0) * lateral[leg];
      p.foot = Vec3(foot2.x(), foot2.y(), ground_at(foot2) + sole[leg]);
      p.stance = true;
      p.touchdown = 0;
      const Real theta = leg_phase(table.gaits[gait[0]], static_cast<Gait>(gait[0]), leg);
      // On its phase after LH, but within the first stance (a whole cycle early if
      // needed), so no foot starts by trailing out of reach.
      p.lift = lh_lift + static_cast<long>(std::lround(theta * T));
      if (p.lift > std::lround(duty(0) * T)) p.lift -= std::lround(T);
      p.lift = std::max(1L, p.lift);
    }
  }

  const int order[kLegCount] = {kLH, kRH, kLF, kRF};  // LH first: the others follow its clock
  std::vector<Vec3> planned(static_cast<std::size_t>(frames) * kLegCount);
  std::vector<Real> contact(static_cast<std::size_t>(frames) * kLegCount);
  std::vector<Real> lift(static_cast<std::size_t>(frames) * kLegCount);
  for (long k = 0; k <= last_step; ++k) {
    const bool gait_changed = k > 0 && gait[k] != gait[k - 1];
    for (int leg : order) {
      LegPlan& p = plan[leg];
      if (!p.stance && k >= p.touchdown) {
        p.stance = true;
        p.foot = p.target;
        p.lift = p.touchdown + std::max(plan_stance(leg, p.touchdown), 1L);
      }
      if (p.stance) {
        if (gait_changed) p.lift = std::max(k + 1, p.touchdown + plan_stance(leg, p.touchdown));
        if (speed[k] < kStandSpeed) p.lift = std::max(p.lift, k + 1);  // standing: the clock waits
        const Vec2d rel = horizontal(p.foot) - root_at(leg, k);
        const Real offset = rel.dot(body[k].heading) - neutral[leg];  // from where the foot stands at rest
        const Real margin = reach[leg] - swing_margin(speed[k], table.gaits[gait[k]]);
        const bool out_of_reach = offset < -margin && speed[k] >= kStandSpeed;
        if (k >= p.lift || out_of_reach) start_swing(leg, k);
      }
    }
    if (k % substeps == 0) {
      const long f = k / substeps;
      for (int leg = 0; leg < kLegCount; ++leg) {
        planned[f * kLegCount + leg] = foot_at(leg, k);
        contact[f * kLegCount + leg] = plan[leg].stance ? 1 : 0;
        lift[f * kLegCount + leg] = lift_at(leg, k);
      }
    }
  }

  // --- body height and pitch per frame ------------------------------------------
  // Bob (seed: measured body bob replayed) as a dip accumulated in phase so a change
  // of cycle time never makes it jump; then the body is lowered wherever a foot, planted
  // or swinging, would be out of its leg's reach, fore and hind apart (that gives pitch).
  // Swinging feet count too: a hoof just lifted far behind its root (at 24 fps a frame
  // can find it there) or about to land far ahead must be reachable.
  std::vector<Real> drop_fore(frames), drop_hind(frames), bob(frames);
  {
    Real phase = 0, amplitude = table.gaits[gait[0]].bob;
    for (int f = 0; f < frames; ++f) {
      const long k = static_cast<long>(f) * substeps;
      const GaitParams& g = table.gaits[gait[k]];
      const Real frame_dt = 1 / in.fps;
      amplitude += (g.bob - amplitude) * std::min(Real(1), frame_dt / 0.3);
      if (f > 0) phase += g.bobs_per_cycle * frame_dt / cycle_time(g) * std::min(Real(1), speed[k] / 0.5);
      const Real fade = std::min(Real(1), speed[k] / 0.5);
      bob[f] = amplitude * fade * (1 - std::cos(2 * kPi * phase)) / 2;
    }
  }
  for (int f = 0; f < frames; ++f) {
    const long k = static_cast<long>(f) * substeps;
    Real need[2] = {0, 0};
    for (int leg = 0; leg < kLegCount; ++leg) {
      const Vec3& foot = planned[f * kLegCount + leg];
      const Vec2d root2 = root_at(leg, k);
      const Real dx = (horizontal(foot) - root2).dot(body[k].heading);
      const Real ground_here = ground_at(root2) - ground_plane;
      const Real root_z = rig.legs[leg].heads[0].z() + ground_here - bob[f];
      Real h = root_z - foot.z();
      for (int it = 0; it < 4; ++it) {
        const Real r = kReachMargin * reach_tables[leg].at(std::atan2(-std::max(h, Real(1e-3)), dx));
        h = std::min(root_z - foot.z(), std::sqrt(std::max(Real(0), r * r - dx * dx)));
      }
      const Real lower = std::max(Real(0), (root_z - foot.z()) - h);
      need[is_fore(leg) ? 0 : 1] = std::max(need[is_fore(leg) ? 0 : 1], lower);
    }
    drop_fore[f] = need[0];
    drop_hind[f] = need[1];
  }
  // Smooth from above: a running max then a running mean of the same width never
  // gives less drop than needed at any frame.
  const int radius = std::max(1, static_cast<int>(std::lround(0.08 * in.fps)));
  auto envelope = [&](std::vector<Real>& drop) {
    std::vector<Real> widened(frames), smooth(frames);
    for (int f = 0; f < frames; ++f) {
      Real m = 0;
      for (int j = std::max(0, f - radius); j <= std::min(frames - 1, f + radius); ++j) m = std::max(m, drop[j]);
      widened[f] = m;
    }
    for (int f = 0; f < frames; ++f) {
      Real sum = 0;
      for (int j = f - radius; j <= f + radius; ++j) sum += widened[std::clamp(j, 0, frames - 1)];
      smooth[f] = sum / (2 * radius + 1);
    }
    drop.swap(smooth);
  };
  envelope(drop_fore);
  envelope(drop_hind);

  // --- per frame: body pose, IK ---------------------------------------------------
  out.angles.assign(static_cast<std::size_t>(frames) * out.bones, 0);
  out.body_location.assign(static_cast<std::size_t>(frames) * 3, 0);
  out.body_rotation.assign(static_cast<std::size_t>(frames) * 4, 0);
  out.contacts.assign(contact.begin(), contact.end());
  out.feet_planned.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.feet.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.roots.assign(static_cast<std::size_t>(frames) * 12, 0);
  out.headings.assign(static_cast<std::size_t>(frames) * 3, 0);
  out.gait.assign(frames, 0);
  out.speed.assign(frames, 0);
  out.ik_error.assign(static_cast<std::size_t>(frames) * 4, 0);

  Real fore_d = 0, hind_d = 0;  // fore-aft distance of the fore / hind roots from the body head
  for (int leg = 0; leg < kLegCount; ++leg) (is_fore(leg) ? fore_d : hind_d) += root_rel[leg].dot(F) / 2;
  std::vector<Real> pose(out.bones);
  for (int leg = 0; leg < kLegCount; ++leg) {
    for (int b = 0; b < chains[leg].size(); ++b) {
      pose[bone_offset[leg] + b] = std::clamp(Real(0), chains[leg].limit_min[b], chains[leg].limit_max[b]);
    }
  }
  std::vector<Mat3> rotations(frames);
  Vec3List heads(frames);
  for (int f = 0; f < frames; ++f) {
    const long k = static_cast<long>(f) * substeps;
    const Frame2& b = body[k];
    // Ground under the fore and hind roots, lowered by bob and reach (see above).
    Real ground_fore = 0, ground_hind = 0;
    for (int leg = 0; leg < kLegCount; ++leg) {
      (is_fore(leg) ? ground_fore : ground_hind) += (ground_at(root_at(leg, k)) - ground_plane) / 2;
    }
    const Real down_fore = bob[f] + drop_fore[f] - ground_fore;
    const Real down_hind = bob[f] + drop_hind[f] - ground_hind;
    const Real span = fore_d - hind_d;
    const Real sin_pitch = span > 1e-6 ? std::clamp((down_fore - down_hind) / span, Real(-0.9), Real(0.9)) : 0;
    const Real pitch = std::asin(sin_pitch);
    const Real lift_head = -down_fore + fore_d * sin_pitch;
    const Real yaw = std::atan2(F2.x() * b.heading.y() - F2.y() * b.heading.x(), F2.dot(b.heading));
    const Mat3 R = (Eigen::AngleAxis<Real>(yaw, up()) * Eigen::AngleAxis<Real>(pitch, A)).toRotationMatrix();
    const Vec3 head(b.head.x(), b.head.y(), rig.body_head.z() + lift_head);
    // Body bone channels: basis = rest^-1 * D * rest, with D(x) = head + R (x - head_rest).
    const Mat3 basis_rot = rig.body_rest.transpose() * R * rig.body_rest;
    const Vec3 basis_loc = rig.body_rest.transpose() * (head - rig.body_head);
    Quat q(basis_rot);
    if (f > 0) {  // keep the quaternion on one side so F-curves interpolate the short way
      const Real* prev = out.body_rotation.data() + (f - 1) * 4;
      if (q.w() * prev[0] + q.x() * prev[1] + q.y() * prev[2] + q.z() * prev[3] < 0) q.coeffs() = -q.coeffs();
    }
    for (int c = 0; c < 3; ++c) out.body_location[f * 3 + c] = basis_loc[c];
    out.body_rotation[f * 4 + 0] = q.w();
    out.body_rotation[f * 4 + 1] = q.x();
    out.body_rotation[f * 4 + 2] = q.y();
    out.body_rotation[f * 4 + 3] = q.z();
    out.gait[f] = gait[k];
    out.speed[f] = speed[k];
    const Vec3 heading3(b.heading.x(), b.heading.y(), 0);
    for (int c = 0; c < 3; ++c) out.headings[f * 3 + c] = heading3[c];
    rotations[f] = R;
    heads[f] = head;
  }
  // IK: each leg runs through the frames in order (warm start), legs in parallel; one
  // thread per leg does the same arithmetic whatever the thread count: deterministic.
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
  parallel_for(kLegCount, 0, 1, [&](std::size_t begin, std::size_t end) {
    for (std::size_t l = begin; l < end; ++l) {
      const int leg = static_cast<int>(l);
      const LegChain& chain = chains[leg];
      const int n = chain.size();
      auto local_goal = [&](int f, const Vec3& goal) {
        const Vec3 local = rotations[f].transpose() * (goal - heads[f]) + rig.body_head;  // rest space
        return Vec2d(local.dot(F), local.z());
      };
      auto record = [&](int f, const Vec3& goal, const Real* angles, Real error) {
        for (int c = 0; c < 3; ++c) out.feet_planned[(f * kLegCount + leg) * 3 + c] = goal[c];
        out.ik_error[f * 4 + leg] = error;
        std::copy(angles, angles + n, out.angles.begin() + static_cast<std::ptrdiff_t>(f) * out.bones + bone_offset[leg]);
      };
      // One frame on from `st` for the foot at `goal2`; returns the miss. The warm start
      // is the previous frame's pose (seed 3.2) carried on by its change from the frame
      // before (a foot's angles move smoothly, so this lands close), or `seed` if given.
      auto advance = [&](LegIkState& st, const Vec2d& goal2, bool planted, bool first_frames, const Real* seed) {
        Real* angles = st.angles;
        if (goal2 == st.last_target) {  // nothing moved (standing): keep the pose exactly
          std::copy(angles, angles + n, st.previous);
          return st.last_error;
        }
        st.last_target = goal2;
        for (int bone = 0; bone < n; ++bone) {
          const Real last = angles[bone];
          angles[bone] = seed ? seed[bone] : first_frames ? last : last + (last - st.previous[bone]);
          st.previous[bone] = last;
        }
        const Real tolerance = planted ? kIkTolerance : kSwingIkTolerance;
        st.last_error = solve_ccd(chain, goal2, in.ccd_iterations, tolerance, angles, planted).error;
        if (!planted && !seed && !first_frames && st.last_error > kSwingTolerance) {
          // At lift-off the foot turns back on its root: carried on, the warm start can
          // overshoot into a limit the solve cannot leave. The plain previous pose then.
          Real plain[kMaxBones];
          std::copy(st.previous, st.previous + n, plain);
          const Real error = solve_ccd(chain, goal2, in.ccd_iterations, tolerance, plain, false).error;
          if (error < st.last_error) {
            std::copy(plain, plain + n, angles);
            st.last_error = error;
          }
        }
        return st.last_error;
      };
      LegIkState state;
      std::copy(pose.data() + bone_offset[leg], pose.data() + bone_offset[leg] + n, state.angles);
      for (int f = 0; f < frames;) {
        if (contact[f * kLegCount + leg] > 0) {
          const Vec3& goal = planned[f * kLegCount + leg];
          record(f, goal, state.angles, advance(state, local_goal(f, goal), true, f < 2, nullptr));
          ++f;
          continue;
        }
        // A swing, frames [f, g), is solved as a whole: see solve_swing below.
        int g = f;
        while (g < frames && contact[g * kLegCount + leg] == 0) ++g;
        const int count = g - f;
        std::vector<Vec3> goals(count);
        std::vector<Vec2d> goals2(count);
        auto set_goals = [&](Real scale) {
          for (int i = 0; i < count; ++i) {
            goals[i] = planned[(f + i) * kLegCount + leg];
            goals[i].z() -= (1 - scale) * lift[(f + i) * kLegCount + leg];
            goals2[i] = local_goal(f + i, goals[i]);
          }
        };
        // Forward from the lift-off pose, frame by frame with the warm start.
        auto forward = [&](SwingTrack& track) {
          track.angles.resize(static_cast<std::size_t>(count) * n);
          track.error.resize(count);
          track.worst = 0;
          LegIkState st = state;
          for (int i = 0; i < count; ++i) {
            track.error[i] = advance(st, goals2[i], false, f + i < 2, nullptr);
            track.worst = std::max(track.worst, track.error[i]);
            std::copy(st.angles, st.angles + n, track.angles.begin() + i * n);
          }
        };
        set_goals(kLiftScales[0]);
        SwingTrack best;
        forward(best);
        Real best_scale = kLiftScales[0];
        if (best.worst > kSwingTolerance) {
          // The warm start folded into a corner of the limits it cannot leave without a
          // jump, or the lift carries the hoof past what the limits allow. The landing
          // pose (what the planted foot's solve, restarts allowed, finds) solved
          // backwards in time gives the other branch; where both follow the path the
          // pose crosses from one to the other, each frame re-solved from a blend of
          // the two. Failing that, the same with less lift. First that follows wins.
          Real landing[kMaxBones];
          std::copy(state.angles, state.angles + n, landing);
          if (g < frames) {
            solve_ccd(chain, local_goal(g, planned[g * kLegCount + leg]), in.ccd_iterations, kIkTolerance, landing, true);
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
            back.angles.resize(static_cast<std::size_t>(count) * n);
            back.error.resize(count);
            LegIkState st;
            std::copy(landing, landing + n, st.angles);
            std::copy(landing, landing + n, st.previous);
            for (int i = count - 1; i >= 0; --i) {
              back.error[i] = advance(st, goals2[i], false, false, nullptr);
              std::copy(st.angles, st.angles + n, back.angles.begin() + i * n);
            }
            int ahead_end = 0;  // frames [0, ahead_end) follow going forward
            while (ahead_end < count && ahead.error[ahead_end] <= kSwingTolerance) ++ahead_end;
            int back_start = count;  // frames [back_start, count) follow going backward
            while (back_start > 0 && back.error[back_start - 1] <= kSwingTolerance) --back_start;
            if (back_start >= ahead_end) continue;  // no frame both follow: no crossing
            const int w0 = back_start, w1 = ahead_end;  // crossing window [w0, w1)
            crossed = ahead;
            crossed.worst = 0;
            LegIkState cs = state;
            for (int i = 0; i < count; ++i) {
              Real seed[kMaxBones];
              const Real* a = ahead.angles.data() + i * n;
              const Real* b = back.angles.data() + i * n;
              const Real t = std::clamp(static_cast<Real>(i - w0 + 1) / (w1 - w0 + 1), Real(0), Real(1));
              const Real w = t * t * (3 - 2 * t);
              for (int bone = 0; bone < n; ++bone) seed[bone] = a[bone] + w * (b[bone] - a[bone]);
              crossed.error[i] = advance(cs, goals2[i], false, false, seed);
              crossed.worst = std::max(crossed.worst, crossed.error[i]);
              std::copy(cs.angles, cs.angles + n, crossed.angles.begin() + i * n);
            }
            if (crossed.worst < best.worst) {
              best = crossed;
              best_scale = scale;
            }
            if (crossed.worst <= kSwingTolerance) break;
          }
          set_goals(best_scale);
        }
        for (int i = 0; i < count; ++i) record(f + i, goals[i], best.angles.data() + i * n, best.error[i]);
        // Carry the warm start on from the swing's last two poses.
        std::copy(best.angles.end() - n, best.angles.end(), state.angles);
        if (count >= 2) std::copy(best.angles.end() - 2 * n, best.angles.end() - n, state.previous);
        state.last_target = goals2[count - 1];
        state.last_error = best.error[count - 1];
        f = g;
      }
    }
  });
  forward_kinematics(rig, frames, out.angles.data(), out.body_location.data(), out.body_rotation.data(),
                     out.feet.data(), out.roots.data());
  return out;
}

}  // namespace kodawari::gait
