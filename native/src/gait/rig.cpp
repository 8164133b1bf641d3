// The rig as the planner reads it: validation, the planar chain of a leg, the ground
// heightfield, and forward kinematics of baked channels (what the report measures).
#include "kodawari/gait/rig.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace kodawari::gait {

namespace {
constexpr int kMaxBones = 6;
Vec3 up() { return Vec3(0, 0, 1); }
}  // namespace

namespace {
// Grid coordinate clamped to [0, top]; NaN (a NaN origin, or inf - inf) maps to 0, so
// the integer cast below never sees NaN or inf (undefined behaviour: a wild index).
Real grid_coordinate(Real f, Real top) { return f > 0 ? (f < top ? f : top) : Real(0); }
}  // namespace

Real Heightfield::at(Real x, Real y) const {
  if (empty() || heights.size() < static_cast<std::size_t>(nx) * static_cast<std::size_t>(ny)) return 0;
  const Real fx = grid_coordinate((x - x0) / cell, Real(nx - 1));
  const Real fy = grid_coordinate((y - y0) / cell, Real(ny - 1));
  const int ix = std::min(nx - 2, static_cast<int>(fx)), iy = std::min(ny - 2, static_cast<int>(fy));
  const Real wx = fx - ix, wy = fy - iy;
  auto h = [&](int i, int j) { return heights[static_cast<std::size_t>(j) * nx + i]; };
  return (h(ix, iy) * (1 - wx) + h(ix + 1, iy) * wx) * (1 - wy) + (h(ix, iy + 1) * (1 - wx) + h(ix + 1, iy + 1) * wx) * wy;
}

std::string validate_rig(const Rig& rig) {
  static const char* names[kLegCount] = {"LF", "RF", "LH", "RH"};
  if (!rig.forward.allFinite() || std::abs(rig.forward.z()) > 1e-6 || std::abs(rig.forward.norm() - 1) > 1e-6) {
    return "the forward direction must be a horizontal unit vector";
  }
  for (int leg = 0; leg < kLegCount; ++leg) {
    const LegRig& l = rig.legs[leg];
    const std::size_t n = l.heads.size();
    std::ostringstream why;
    if (n < 2 || n > kMaxBones) {
      why << "leg " << names[leg] << " has " << n << " bone(s); a leg needs 2 to 6";
    } else if (l.limit_min.size() != n || l.limit_max.size() != n || l.stiffness.size() != n) {
      why << "leg " << names[leg] << ": limits and stiffness need one value per bone";
    } else {
      for (std::size_t k = 0; k < n && why.str().empty(); ++k) {
        const Vec3 next = k + 1 < n ? l.heads[k + 1] : l.tail;
        const Vec3 bone = next - l.heads[k];
        const Real planar = std::hypot(bone.dot(rig.forward), bone.z());
        if (!(planar > 1e-4)) why << "leg " << names[leg] << ": bone " << k << " has zero length in the leg's plane";
        if (!(l.limit_min[k] <= l.limit_max[k])) why << "leg " << names[leg] << ": bone " << k << " has limit_min > limit_max";
        if (!(l.stiffness[k] > 0 && l.stiffness[k] <= 1)) why << "leg " << names[leg] << ": stiffness must be in (0, 1]";
      }
    }
    if (!why.str().empty()) return why.str();
  }
  return {};
}

LegChain make_chain(const Rig& rig, int leg) {
  const LegRig& l = rig.legs[leg];
  LegChain chain;
  const int n = static_cast<int>(l.heads.size());
  chain.root = Vec2(l.heads[0].dot(rig.forward), l.heads[0].z());
  for (int k = 0; k < n; ++k) {
    const Vec3 next = k + 1 < n ? l.heads[k + 1] : l.tail;
    const Vec3 bone = next - l.heads[k];
    const Real f = bone.dot(rig.forward), u = bone.z();
    chain.lengths.push_back(std::hypot(f, u));
    chain.rest_direction.push_back(std::atan2(u, f));
  }
  chain.limit_min = l.limit_min;
  chain.limit_max = l.limit_max;
  chain.stiffness = l.stiffness;
  return chain;
}
void forward_kinematics(const Rig& rig, int frames, const Real* angles, const Real* body_location,
                        const Real* body_rotation, Real* feet, Real* roots) {
  const Vec3 F = rig.forward;
  const Vec3 A = up().cross(F);
  std::array<LegChain, kLegCount> chains;
  int bones = 0;
  std::array<int, kLegCount> offset{};
  for (int leg = 0; leg < kLegCount; ++leg) {
    chains[leg] = make_chain(rig, leg);
    offset[leg] = bones;
    bones += chains[leg].size();
  }
  for (int f = 0; f < frames; ++f) {
    const Real* q = body_rotation + f * 4;
    Quat basis(q[0], q[1], q[2], q[3]);
    const Real norm = basis.norm();
    basis = norm > 0 ? Quat(basis.coeffs() / norm) : Quat::Identity();
    const Vec3 loc(body_location[f * 3], body_location[f * 3 + 1], body_location[f * 3 + 2]);
    // D = rest * basis * rest^-1 in armature space.
    const Mat3 R = rig.body_rest * basis.toRotationMatrix() * rig.body_rest.transpose();
    const Vec3 head = rig.body_head + rig.body_rest * loc;
    auto apply = [&](const Vec3& rest_point) -> Vec3 { return head + R * (rest_point - rig.body_head); };
    for (int leg = 0; leg < kLegCount; ++leg) {
      const Vec2 foot2 = chain_foot(chains[leg], angles + static_cast<std::size_t>(f) * bones + offset[leg]);
      const Real lat = rig.legs[leg].tail.dot(A);
      const Vec3 foot_rest = F * foot2.x() + up() * foot2.y() + A * lat;
      const Vec3 foot = apply(foot_rest), root = apply(rig.legs[leg].heads[0]);
      for (int c = 0; c < 3; ++c) {
        feet[(f * kLegCount + leg) * 3 + c] = foot[c];
        roots[(f * kLegCount + leg) * 3 + c] = root[c];
      }
    }
  }
}
}  // namespace kodawari::gait
