// Private to the rod solver's source files: the particle layout's helpers and the
// constants shared by lifecycle, rest shape and simulation (see rod_system.hpp for
// the particle layout: ghost, root, joints, tip).
#pragma once

#include <algorithm>
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
// relative to the root in it (rod_simulate.cpp). Measured: 1.5 keeps strands of 16-64 bones
// without damping from gaining energy; 2 does not.
constexpr Real kMaxTravel = 1.5;
// ... or when the chain's tension would make its string mode outrun the substep
// (docs/algorithms.md §3.3): n g Δt² / l, n the joints the root bone carries, must stay
// below this. Position projection with v = Δx/Δt resolves the mode ω² ≈ 4 n g / l only
// while ω Δt < 2, i.e. n g Δt² / l < 1. Measured: 1 keeps hanging 32-64-bone strands with
// damping 20 from gaining energy and splits no strand of 16 bones of 2 cm or longer at the
// default 4 substeps; with no such split they gain up to 0.06 J a frame.
constexpr Real kMaxTension = 1.0;
// ... or when gravity alone would drop a joint by more than this many bone lengths in one.
constexpr Real kMaxDrop = 0.15;
constexpr int kMaxSplit = 32;
// Stiffness per unit mass (1/s²) that the shape-matching fraction of a substep stands for,
// read as one implicit Euler step of a spring (s = κΔt² / (1 + κΔt²)): the coefficient of the
// shape-matching energy (rod_energy.cpp). The fraction compounds over the iterations; a
// fraction of 1 is a hard constraint, read as 0.99.
inline Real shape_stiffness(const RodParams& p) {
  const Real dt = 1 / (kSubstepUnit * Real(p.substeps));
  const Real left = std::max(std::pow(Real(1) - p.stiffness, Real(p.iterations)), Real(0.01));
  return (1 - left) / (left * dt * dt);
}
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
