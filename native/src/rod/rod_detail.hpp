// Private to the rod solver's source files: the particle layout's helpers and the
// constants shared by lifecycle, rest shape and simulation (see rod_system.hpp for
// the particle layout: ghost, root, joints, tip).
#pragma once

#include <algorithm>
#include <cmath>
#include <limits>

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

// The energy of docs/algorithms.md §3.3 (rod_energy.cpp), shared by RodSystem::energy and the
// solver's per-frame energy budget so both measure exactly the same quantity.
// The kinematic root's rigid motion over a frame: velocity V at `origin`, spin Ω.
struct RigidMotion {
  Vec3 origin = Vec3::Zero();
  Vec3 velocity = Vec3::Zero();
  Vec3 spin = Vec3::Zero();
};
// a²/5 of the ellipsoid term, a the mean segment length.
Real ellipsoid_term(const ChainGeometry& geometry);
// Kinetic energy of the dynamic particles relative to `frame` (the Jacobi integral's kinetic
// part; the plain kinetic energy for a frame at rest).
Real chain_kinetic(std::size_t count, const Vec3* x, const Vec3* v, const Vec3* omega, Real e,
                   const RigidMotion& frame);
// Gravitational -Σ g·x_j and shape-matching (κ/3) Σ_c U_c energies of the particles. With
// `pull`, also Σ_c w_i (g_ci - x_i) per particle (-3/κ times the shape-matching gradient); with
// `turn`, the sum of the orientations R_c q̄_i its groups pull each particle towards (x, y, z, w).
void chain_potential(std::size_t count, const Vec3* x, const Quat* q, const Vec3* x_rest, const Quat* q_rest, Real e,
                     Real kappa, const Vec3& g, Real& gravitational, Real& shape_matching, Vec3* pull = nullptr,
                     Eigen::Matrix<Real, 4, 1>* turn = nullptr, const Quat* guesses = nullptr);

// The energy budget (rod_energy_budget.cpp, docs/algorithms.md §3.3): the energy a window of
// 1/24 s may end with, relative to the root's rigid motion over it.
struct EnergyBudget {
  RigidMotion motion;  // the root's motion over the window (origin: the root at its end)
  Real energy = 0;
};
struct BudgetScratch {
  Vec3List x_carried, x_trial;
  QuatList q_carried, q_trial;
};
// Opens a window on the state now (root at origin, rotation; `shape` its shape-matching energy;
// gravity the solver's, asleep as EnergyWindow::asleep), `phase` base substeps into its 1/24 s
// (0, or where the one it replaces had got to when the rest shape changed).
void open_energy_window(std::size_t count, RodState& s, const Vec3& origin, const Quat& rotation, Real shape,
                        const Vec3& gravity, bool asleep, int phase);
// Closes the window `duration` seconds after it opened, the root now at origin, rotation:
// brings the state back within the budget if it ended above it. Returns the shape-matching
// energy of the state kept (to open the next window with); `guesses` (may be null): each group's
// rotation from the solver's last iteration, to start its fit from; `rests` when it put the state back
// where the window began with the root still (the next window may sleep).
Real close_energy_window(std::size_t count, RodState& s, const Vec3* x_rest, const Quat* q_rest, const Real* lengths,
                         Real e, Real kappa, const Vec3& g, const Vec3& origin, const Quat& rotation, Real duration,
                         const std::vector<Collider>& colliders, Real radius, const Quat* guesses,
                         BudgetScratch& scratch, bool& rests);

// Rest particles in the anchor frame (see the header for the particle layout).
void rest_particles(const ChainGeometry& g, const QuatList& rest, Vec3List& x_rest, QuatList& q_rest);

// Bone frames of the current state: each particle's orientation turned so the bone
// axis lies along its actual segment.
void bone_frames(const ChainGeometry& g, const RodState& s, QuatList& frames);


}  // namespace kodawari::rod::detail
