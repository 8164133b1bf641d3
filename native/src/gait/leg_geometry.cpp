// The legs as the planner measures them: chains, reach, rest offsets.
#include <cmath>
#include <limits>

#include "bake_stages.hpp"

namespace kodawari::gait::stages {

namespace {
constexpr int kReachSamples = 64;
}  // namespace

Real Reach::at(Real angle) const {
  const Real x = std::clamp((angle + kPi) / kPi, Real(0), Real(1)) * (kReachSamples - 1);
  const int i = std::min(kReachSamples - 2, static_cast<int>(x));
  const Real w = x - i;
  return table[i] * (1 - w) + table[i + 1] * w;
}

LegGeometry measure_legs(const Rig& rig, const GaitTable& table) {
  LegGeometry legs;
  const Vec3 F = rig.forward;
  const Vec3 A = up().cross(F);  // lateral hinge axis
  legs.ground_plane = std::numeric_limits<Real>::infinity();
  for (int leg = 0; leg < kLegCount; ++leg) legs.ground_plane = std::min(legs.ground_plane, rig.legs[leg].tail.z());
  for (int leg = 0; leg < kLegCount; ++leg) {
    legs.chains[leg] = make_chain(rig, leg);
    legs.bone_offset[leg] = legs.bones;
    legs.bones += legs.chains[leg].size();
    const Vec3 root = rig.legs[leg].heads[0], foot = rig.legs[leg].tail;
    legs.reach[leg] = table.reach * legs.chains[leg].length();
    legs.neutral[leg] = (foot - root).dot(F);
    legs.lateral[leg] = (foot - root).dot(A);
    legs.sole[leg] = foot.z() - legs.ground_plane;
    legs.root_rel[leg] = root - rig.body_head;
    legs.reach_tables[leg].table.resize(kReachSamples);
    for (int i = 0; i < kReachSamples; ++i) {
      const Real angle = -kPi + kPi * i / (kReachSamples - 1);
      legs.reach_tables[leg].table[i] = directional_reach(legs.chains[leg], Vec2d(std::cos(angle), std::sin(angle)));
    }
    if (!is_fore(leg)) legs.leg_length = std::max(legs.leg_length, root.z() - foot.z());
  }
  return legs;
}

Real ground_at(const BakeInput& in, const LegGeometry& legs, const Vec2d& p) {
  return in.ground.empty() ? legs.ground_plane : in.ground.at(p.x(), p.y());
}

}  // namespace kodawari::gait::stages
