// Private to the rod solver's source files: the particle layout's helpers and the
// constants shared by lifecycle, rest shape and simulation (see rod_system.hpp for
// the particle layout: ghost, root, joints, tip).
#pragma once

#include <cmath>

#include "kodawari/rod/rod_system.hpp"

namespace kodawari::rod::detail {

// Ghost and root are kinematic; their larger weight in each group fit makes the
// root bone hold its rest direction relative to the parent more firmly.
constexpr Real kKinematicWeight = 4.0;
// Wind acts as drag towards the wind velocity: a = kWindDrag * (wind - v).
constexpr Real kWindDrag = 1.5;
// Gust frequency (Hz) and strength of the GLM Perlin noise that modulates the wind.
constexpr Real kGustFrequency = 0.7;
constexpr Real kGustAmount = 0.6;
// Substep rate unit: `substeps` counts substeps per 1/24 s, whatever the scene's fps.
constexpr Real kSubstepUnit = 24.0;
constexpr long kMaxSubstepsPerFrame = 4096;
// A substep is split when a joint would move more than this many (shortest) bone lengths
// relative to the root in it, into at most kMaxSplit parts (rod_simulate.cpp). Measured:
// 1.5 keeps strands of 16-64 bones without damping from gaining energy; 2 does not.
constexpr Real kMaxTravel = 1.5;
constexpr int kMaxSplit = 16;
// ... or when gravity would drop a joint by more than this many bone lengths in one.
// Measured: 0.25 let 64-bone strands gain energy at 1 substep; 0.1 splits the default
// substeps of 0.6 m strands of 64 bones and slows their settling past 10 s.
constexpr Real kMaxDrop = 0.15;
// Rods per work chunk (threads take chunks as they go): about 0.2 ms of work at 16 bones.
constexpr std::size_t kRodsPerChunk = 16;

inline bool finite(const Vec3& v) { return v.allFinite(); }

// q / |q| with one division (Eigen's normalized() divides every coefficient): the
// substep loop normalises three quaternions per particle.
inline Quat unit(const Quat& q) {
  Quat out;
  out.coeffs() = q.coeffs() * (Real(1) / std::sqrt(q.coeffs().squaredNorm()));
  return out;
}
inline bool finite(const Quat& q) { return q.coeffs().allFinite(); }

// Spin integration to first order, q <- normalise([1, ω dt / 2] q), and its exact inverse
// ω = 2 vec(dq) / (w(dq) dt): consistent with each other and free of sin/cos/atan2, which
// matters at tens of thousands of particles per substep (dt ω is small at these rates).
inline Quat spin(const Quat& q, const Vec3& rotation_vector) {
  const Vec3 half = rotation_vector / 2;
  return unit(Quat(1, half.x(), half.y(), half.z()) * q);
}

// Angular velocity that turns `from` into `to` in dt (inverse of spin).
inline Vec3 angular_velocity(const Quat& from, const Quat& to, Real dt) {
  Quat dq = to * from.conjugate();
  if (dq.w() < 0) dq.coeffs() = -dq.coeffs();
  if (dq.w() < 1e-6) return Vec3::Zero();  // a half turn in one substep: no meaningful spin
  return dq.vec() * (2 / (dq.w() * dt));
}

// Rest particles in the anchor frame (see the header for the particle layout).
void rest_particles(const ChainGeometry& g, const QuatList& rest, Vec3List& x_rest, QuatList& q_rest);

// Bone frames of the current state: each particle's orientation turned so the bone
// axis lies along its actual segment.
void bone_frames(const ChainGeometry& g, const RodState& s, QuatList& frames);


}  // namespace kodawari::rod::detail
