// Stateless kernels of oriented-particle shape matching (Müller & Chentanez 2011)
// with PBD distance constraints and collision projection, as used by RodSystem.
#pragma once

#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::rod {

// The rotational part of A, found by the iterative method of Müller et al. 2016
// ("A robust method to extract the rotational part of deformations"), warm-started
// from `guess`. Deterministic: a fixed iteration cap and a fixed tolerance.
Quat extract_rotation(const Mat3& A, const Quat& guess, int max_iterations = 24);

// The rotational part of A (det A > 0) to round-off, by Higham's scaled Newton iteration
// X <- (γ X + X⁻ᵀ / γ) / 2, γ = (|X⁻¹|_F / |X|_F)^½ (Higham 1986): quadratic convergence, a
// few 3x3 inversions, where extract_rotation converges linearly when A is far from a rotation
// (as a chain group's fit is). False (R untouched) when det A <= 0 or it did not converge.
bool polar_rotation(const Mat3& A, Mat3& R);

// The same rotation by Newton's method on tr(Rᵀ A) over rotations R = R₀ exp([ω]×), from a
// guess R near it: ω = (tr S I - S)⁻¹ g with M = R₀ᵀ A, S = sym M, g = (M₂₁ - M₁₂, M₀₂ - M₂₀,
// M₁₀ - M₀₁). Quadratic from a close guess (a group's rotation from the solver's last
// iteration): two or three steps where polar_rotation needs four or five inversions. False
// (R untouched) when it did not converge in `steps`.
bool refine_rotation(const Mat3& A, const Quat& guess, Mat3& R, int steps = 4);

// PBD distance constraint between a and b with inverse masses wa, wb (inline: the
// substep loop calls it once per segment).
inline void project_distance(Vec3& a, Vec3& b, Real wa, Real wb, Real rest_length) {
  const Real wsum = wa + wb;
  if (wsum <= 0) return;
  const Vec3 d = b - a;
  const Real len = d.norm();
  if (len < 1e-12) return;
  const Vec3 correction = (len - rest_length) / (len * wsum) * d;
  a += wa * correction;
  b -= wb * correction;
}

struct Collider {
  Vec3 start;         // sphere centre, or capsule axis start
  Vec3 end;           // capsule axis end (== start for a sphere)
  Real radius = 0.0;  // collider radius (the rod's radius is added as margin)
};

// Pushes p out of every collider inflated by `margin`; true when it moved.
bool push_out_of_colliders(Vec3& p, const std::vector<Collider>& colliders, Real margin);

// Minimal rotation taking unit vector a to unit vector b, applied before q:
// keeps q's twist about a while aligning a with b.
Quat align_axis(const Quat& q, const Vec3& axis_local, const Vec3& target_direction);

}  // namespace kodawari::rod
