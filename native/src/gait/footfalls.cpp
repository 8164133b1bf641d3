// The footfalls (seed 3.1, 3.3): a phase clock per leg on the planner's grid; a planted
// foot is fixed in the world; a swinging foot travels from its lift-off point to a
// landing point sized by the seed's eq. 3.6 along the swing path with the gait's lift.
#include <cmath>

#include "bake_stages.hpp"
#include "kodawari/gait/swing_path.hpp"

namespace kodawari::gait::stages {

namespace {

constexpr Real kStandSpeed = 1e-4;  // below this the clocks of planted legs pause

struct LegPlan {
  bool stance = true;
  long lift = 0;          // planned lift-off step (stance)
  long touchdown = 0;     // touchdown step of the current stance, or planned for a swing
  long next_stance = 0;   // stance length planned for after the current swing
  long swing_start = 0, swing_length = 1;
  Vec3 foot = Vec3::Zero();   // planted foot, or swing start
  Vec3 target = Vec3::Zero();  // swing landing point
  Real swing_height = 0, swing_peak = 0.5, ease = kEaseMax;
  bool strike = false;  // lands with downward speed (a gait with a flight phase)
};

// The four clocks and the rules that move them.
class FootfallPlanner {
 public:
  FootfallPlanner(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track)
      : in_(in), table_(in.table), legs_(legs), track_(track) {}

  // Start planted on the rest feet, LH half-way through its stance, the others on
  // their phases after it.
  void start() {
    const Real T = cycle_steps(0);
    const long lh_lift = std::max(1L, static_cast<long>(std::lround(0.5 * duty(0) * T)));
    for (int leg = 0; leg < kLegCount; ++leg) {
      LegPlan& p = plan_[leg];
      const Vec2d foot2 = track_.root_at(leg, 0) + track_.body[0].heading * legs_.neutral[leg] +
                          track_.lateral_dir(0) * legs_.lateral[leg];
      p.foot = Vec3(foot2.x(), foot2.y(), ground_at(in_, legs_, foot2) + legs_.sole[leg]);
      p.stance = true;
      p.touchdown = 0;
      const int g = track_.gait[0];
      const Real theta = leg_phase(table_.gaits[g], static_cast<Gait>(g), leg);
      // On its phase after LH, but within the first stance (a whole cycle early if
      // needed), so no foot starts by trailing out of reach.
      p.lift = lh_lift + static_cast<long>(std::lround(theta * T));
      if (p.lift > std::lround(duty(0) * T)) p.lift -= std::lround(T);
      p.lift = std::max(1L, p.lift);
    }
  }

  // Step k: land the swings that are due, lift the stances that are due (or about to
  // leave their reach).
  void step(long k) {
    const std::vector<int>& gait = track_.gait;
    const bool gait_changed = k > 0 && gait[k] != gait[k - 1];
    const int order[kLegCount] = {kLH, kRH, kLF, kRF};  // LH first: the others follow its clock
    for (int leg : order) {
      LegPlan& p = plan_[leg];
      if (!p.stance && k >= p.touchdown) {
        p.stance = true;
        p.foot = p.target;
        p.lift = p.touchdown + std::max(plan_stance(leg, p.touchdown), 1L);
      }
      if (p.stance) {
        const Real v = track_.speed[k];
        if (gait_changed) p.lift = std::max(k + 1, p.touchdown + plan_stance(leg, p.touchdown));
        if (v < kStandSpeed) p.lift = std::max(p.lift, k + 1);  // standing: the clock waits
        const Vec2d rel = horizontal(p.foot) - track_.root_at(leg, k);
        const Real offset = rel.dot(track_.body[k].heading) - legs_.neutral[leg];  // from where it stands at rest
        const Real margin = legs_.reach[leg] - swing_margin(v, table_.gaits[gait[k]]);
        const bool out_of_reach = offset < -margin && v >= kStandSpeed;
        if (k >= p.lift || out_of_reach) start_swing(leg, k);
      }
    }
  }

  bool planted(int leg) const { return plan_[leg].stance; }

  Real lift_at(int leg, long k) const {  // height of a swinging foot above its ground path
    const LegPlan& p = plan_[leg];
    if (p.stance) return 0;
    return p.swing_height * swing_lift(static_cast<Real>(k - p.swing_start) / p.swing_length, p.swing_peak, p.strike);
  }

  Vec3 foot_at(int leg, long k) const {
    const LegPlan& p = plan_[leg];
    if (p.stance) return p.foot;
    const Real s = static_cast<Real>(k - p.swing_start) / p.swing_length;
    const Real w = swing_progress(s, p.ease);
    Vec3 x = p.foot + (p.target - p.foot) * w;
    x.z() += lift_at(leg, k);
    return x;
  }

 private:
  const GaitParams& params_at(long k) const { return table_.gaits[track_.gait[track_.clamp_step(k)]]; }
  Real cycle_steps(long k) const { return cycle_time(params_at(k).swing_time, duty(k)) / track_.dt; }
  Real duty(long k) const {
    const long c = track_.clamp_step(k);
    return duty_at(table_, static_cast<Gait>(track_.gait[c]), track_.speed[c], legs_.leg_length);
  }
  static Real swing_margin(Real v, const GaitParams& p) { return ease_lag(v, p.swing_time); }

  Real lh_next_lift() const {
    const LegPlan& lh = plan_[kLH];
    return lh.stance ? Real(lh.lift) : Real(lh.touchdown + lh.next_stance);
  }

  // Stance length for `leg` touching down at step t1: the gait's alpha T, shifted so
  // the lift-off lands on the gait's phase relative to LH (seed 3.3: "add the timing
  // difference to the current or next stance"). The shift is at most half a cycle;
  // what the reach guard cuts off is caught up on the next stride.
  long plan_stance(int leg, long t1) const {
    const Real T = cycle_steps(t1);
    const Real nominal = duty(t1) * T;
    Real length = nominal;
    if (leg != kLH) {
      const Real ref = lh_next_lift();
      const int g = track_.gait[track_.clamp_step(t1)];
      const Real theta = leg_phase(table_.gaits[g], static_cast<Gait>(g), leg);
      const Real cycles = std::round((t1 + nominal - ref - theta * T) / T);
      length = ref + (theta + cycles) * T - t1;
    }
    return std::max(std::max(1L, static_cast<long>(std::lround(0.35 * nominal))), static_cast<long>(std::lround(length)));
  }

  void start_swing(int leg, long k) {
    LegPlan& p = plan_[leg];
    const GaitParams& g = params_at(k);
    const Real dt = track_.dt;
    p.stance = false;
    p.swing_start = k;
    p.swing_length = std::max(1L, static_cast<long>(std::lround(g.swing_time / dt)));
    p.touchdown = k + p.swing_length;
    p.next_stance = plan_stance(leg, p.touchdown);
    {
      // At speed the reach caps how long a stance can last (2 x margin of travel). A
      // phase shift the stance cannot absorb is taken by this swing, stretched by at
      // most a half (the rest waits for the next stride).
      const Real v = std::max(track_.speed[track_.clamp_step(p.touchdown)], Real(1e-6));
      const Real longest = 2 * (legs_.reach[leg] - swing_margin(v, g)) / v / dt;
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
    const Real stance_travel =
        track_.distance[track_.clamp_step(td + p.next_stance)] - track_.distance[track_.clamp_step(td)];
    const Real v_td = track_.speed[track_.clamp_step(td)];
    const Real margin = legs_.reach[leg] - swing_margin(v_td, g);
    const Real offset = legs_.neutral[leg] + std::clamp(stance_travel / 2, -margin, margin);
    const Vec2d land =
        track_.root_at(leg, td) + track_.at(td).heading * offset + track_.lateral_dir(td) * legs_.lateral[leg];
    p.target = Vec3(land.x(), land.y(), ground_at(in_, legs_, land) + legs_.sole[leg]);
    p.swing_height = g.swing_height;
    p.swing_peak = g.swing_peak;
    // In a gait whose stances take less than half the cycle (canter, gallop) the body
    // flies between them: a foot leaves the ground fast and comes down at speed. A
    // soft landing holds it just above the ground for the swing's last frame while its
    // stance then sweeps the leg back (docs/algorithms.md §4.6, §4.8).
    p.strike = duty(k) < 0.5;
    p.ease = swing_ease(std::max(track_.speed[track_.clamp_step(k)], v_td), g.swing_time);
  }

  const BakeInput& in_;
  const GaitTable& table_;
  const LegGeometry& legs_;
  const BodyTrack& track_;
  std::array<LegPlan, kLegCount> plan_;
};

}  // namespace

Footfalls plan_footfalls(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track) {
  const int frames = static_cast<int>(in.target_speed.size());
  Footfalls feet;
  feet.planned.resize(static_cast<std::size_t>(frames) * kLegCount);
  feet.contact.resize(static_cast<std::size_t>(frames) * kLegCount);
  feet.lift.resize(static_cast<std::size_t>(frames) * kLegCount);
  FootfallPlanner planner(in, legs, track);
  planner.start();
  for (long k = 0; k <= track.last_step; ++k) {
    planner.step(k);
    if (k % track.substeps == 0) {  // a frame: sample the plan
      const long f = k / track.substeps;
      for (int leg = 0; leg < kLegCount; ++leg) {
        feet.planned[f * kLegCount + leg] = planner.foot_at(leg, k);
        feet.contact[f * kLegCount + leg] = planner.planted(leg) ? 1 : 0;
        feet.lift[f * kLegCount + leg] = planner.lift_at(leg, k);
      }
    }
  }
  return feet;
}

}  // namespace kodawari::gait::stages
