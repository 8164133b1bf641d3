// The body's height per frame: the gait's bob, and how far its fore and hind ends are
// lowered so that every foot stays within its leg's reach (which gives pitch).
#include <cmath>

#include "bake_stages.hpp"

namespace kodawari::gait::stages {

namespace {

constexpr Real kMaxDropPitch = 5 * kPi / 180;  // most pitch lowering for reach may add

// Bob (seed: measured body bob replayed) as a dip accumulated in phase, so a change of
// cycle time never makes it jump; faded in from a stand.
std::vector<Real> plan_bob(const BakeInput& in, const BodyTrack& track, const LegGeometry& legs, int frames) {
  const GaitTable& table = in.table;
  std::vector<Real> bob(frames);
  Real phase = 0, amplitude = table.gaits[track.gait[0]].bob;
  for (int f = 0; f < frames; ++f) {
    const long k = static_cast<long>(f) * track.substeps;
    const GaitParams& g = table.gaits[track.gait[k]];
    const Real frame_dt = 1 / in.fps;
    amplitude += (g.bob - amplitude) * std::min(Real(1), frame_dt / 0.3);
    const Real duty = duty_at(table, static_cast<Gait>(track.gait[k]), track.speed[k], legs.leg_length);
    const Real T = cycle_time(g.swing_time, duty);
    if (f > 0) phase += g.bobs_per_cycle * frame_dt / T * std::min(Real(1), track.speed[k] / 0.5);
    const Real fade = std::min(Real(1), track.speed[k] / 0.5);
    bob[f] = amplitude * fade * (1 - std::cos(2 * kPi * phase)) / 2;
  }
  return bob;
}

// Smooth from above: a running max then a running mean of the same width never gives
// less drop than needed at any frame.
void envelope(std::vector<Real>& drop, int radius) {
  const int frames = static_cast<int>(drop.size());
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
}

}  // namespace

BodyHeight plan_body_height(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track,
                            const Footfalls& feet) {
  const int frames = static_cast<int>(in.target_speed.size());
  BodyHeight height;
  height.bob = plan_bob(in, track, legs, frames);
  height.drop_fore.resize(frames);
  height.drop_hind.resize(frames);
  // Lowered wherever a foot, planted or swinging, would be out of its leg's reach, fore
  // and hind apart. Swinging feet count too: a hoof just lifted far behind its root (at
  // 24 fps a frame can find it there) or about to land far ahead must be reachable.
  for (int f = 0; f < frames; ++f) {
    const long k = static_cast<long>(f) * track.substeps;
    Real need[2] = {0, 0};
    for (int leg = 0; leg < kLegCount; ++leg) {
      const Vec3& foot = feet.planned[f * kLegCount + leg];
      const Vec2d root2 = track.root_at(leg, k);
      const Real dx = (horizontal(foot) - root2).dot(track.body[k].heading);
      const Real ground_here = ground_at(in, legs, root2) - legs.ground_plane;
      const Real root_z = in.rig.legs[leg].heads[0].z() + ground_here - height.bob[f];
      Real h = root_z - foot.z();
      for (int it = 0; it < 4; ++it) {
        const Real r = kReachMargin * legs.reach_tables[leg].at(std::atan2(-std::max(h, Real(1e-3)), dx));
        h = std::min(root_z - foot.z(), std::sqrt(std::max(Real(0), r * r - dx * dx)));
      }
      const Real lower = std::max(Real(0), (root_z - foot.z()) - h);
      need[is_fore(leg) ? 0 : 1] = std::max(need[is_fore(leg) ? 0 : 1], lower);
    }
    height.drop_fore[f] = need[0];
    height.drop_hind[f] = need[1];
  }
  // The ends are lowered level rather than pitched: one end is never lowered more than
  // kMaxDropPitch of pitch beyond the other (the other is lowered too, never raised), so
  // a leg short of reach bends both ends' legs instead of tipping the body.
  Real span = 0;
  for (int leg = 0; leg < kLegCount; ++leg) span += (is_fore(leg) ? 0.5 : -0.5) * legs.root_rel[leg].dot(in.rig.forward);
  const Real cap = std::abs(span) * std::sin(kMaxDropPitch);
  for (int f = 0; f < frames; ++f) {
    const Real fore = height.drop_fore[f], hind = height.drop_hind[f];
    height.drop_fore[f] = std::max(fore, hind - cap);
    height.drop_hind[f] = std::max(hind, fore - cap);
  }
  const int radius = std::max(1, static_cast<int>(std::lround(0.08 * in.fps)));
  envelope(height.drop_fore, radius);
  envelope(height.drop_hind, radius);
  return height;
}

}  // namespace kodawari::gait::stages
