#include "kodawari/rod/inextensibility.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "kodawari/rod/oriented_particles.hpp"

namespace kodawari::rod {

namespace {
// Relative length error at which the Newton steps stop: what is left is closed by the
// joint-by-joint pass in rod_simulate.cpp, which then moves joints by micrometres.
constexpr Real kConverged = 1e-5;
// Relative length error beyond which the Gauss-Seidel sweeps run before the Newton steps.
constexpr Real kFar = 1e-3;
}  // namespace

bool project_chain_lengths(Vec3* x, std::size_t count, const Real* lengths, const Real* inverse_mass,
                           Real* scratch, int newton_steps, int sweeps) {
  if (count < 2) return true;
  const std::size_t m = count - 1;  // constraints
  Real* diag = scratch;             // S_kk, then the Thomas pivots
  Real* upper = scratch + m;        // S_k,k+1
  Real* rhs = scratch + 2 * m;      // -C_k, then lambda_k
  Real* normals = scratch + 3 * m;  // n_k (3 per constraint) of the linearisation point
  Vec3* best = reinterpret_cast<Vec3*>(scratch + 6 * m);  // the positions closest so far
  Real best_worst = std::numeric_limits<Real>::infinity();
  auto worst_error = [&] {
    Real worst = 0;
    for (std::size_t k = 0; k < m; ++k) worst = std::max(worst, std::abs((x[k + 1] - x[k]).norm() - lengths[k]) / lengths[k]);
    return worst;
  };
  for (int step = 0; step < newton_steps; ++step) {
    // S = J M^-1 J^T (tridiagonal) and -C. Segment k joins x[k] (gradient -n_k) and x[k+1]
    // (+n_k); segments k and k+1 share x[k+1]: S_k,k+1 = -w_{k+1} n_k . n_{k+1}.
    Real worst = 0;
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 d = x[k + 1] - x[k];
      const Real len = d.norm();
      const Vec3 normal = len > 1e-12 ? Vec3(d / len) : Vec3::Zero();
      normals[3 * k] = normal.x();
      normals[3 * k + 1] = normal.y();
      normals[3 * k + 2] = normal.z();
      diag[k] = inverse_mass[k] + inverse_mass[k + 1];
      if (k > 0) {
        const Real* previous = normals + 3 * (k - 1);
        const Real cosine = previous[0] * normal.x() + previous[1] * normal.y() + previous[2] * normal.z();
        upper[k - 1] = -inverse_mass[k] * cosine;
      }
      rhs[k] = lengths[k] - len;
      const Real error = std::abs(rhs[k]) / lengths[k];
      if (error > worst) worst = error;
    }
    if (worst < kConverged) return true;
    if (worst < best_worst) {
      best_worst = worst;
      std::copy(x, x + count, best);
    }
    if (worst > kFar && sweeps > 0) {
      // Far from the manifold (a fast tip moves bones' lengths per substep on long chains)
      // a linearisation means little: Gauss-Seidel sweeps of the same mass-weighted distance
      // projection (PBD, each an exact local projection) bring the chain close first.
      for (int sweep = 0; sweep < sweeps; ++sweep) {
        for (std::size_t k = 0; k < m; ++k) {
          project_distance(x[k], x[k + 1], inverse_mass[k], inverse_mass[k + 1], lengths[k]);
        }
        for (std::size_t k = m; k-- > 0;) {
          project_distance(x[k], x[k + 1], inverse_mass[k], inverse_mass[k + 1], lengths[k]);
        }
      }
      sweeps = 0;
      --step;  // the sweeps do not count as a Newton step
      continue;
    }
    // Thomas algorithm (S is symmetric positive definite: no pivoting needed).
    for (std::size_t k = 1; k < m; ++k) {
      if (!(diag[k - 1] > 0)) continue;
      const Real factor = upper[k - 1] / diag[k - 1];
      diag[k] -= factor * upper[k - 1];
      rhs[k] -= factor * rhs[k - 1];
    }
    for (std::size_t k = m; k-- > 0;) {
      Real value = rhs[k];
      if (k + 1 < m) value -= upper[k] * rhs[k + 1];
      rhs[k] = diag[k] > 0 ? value / diag[k] : Real(0);
    }
    // dx = M^-1 J^T lambda.
    for (std::size_t k = 0; k < m; ++k) {
      const Vec3 push = rhs[k] * Vec3(normals[3 * k], normals[3 * k + 1], normals[3 * k + 2]);
      x[k] -= inverse_mass[k] * push;
      x[k + 1] += inverse_mass[k + 1] * push;
    }
  }
  // Not converged in newton_steps: far from the manifold on a long, bent chain the
  // linearisation can mislead (its corrections add up along the chain). Keep the closest
  // positions seen; the caller closes what is left joint by joint.
  const Real worst = worst_error();
  if (worst < kConverged) return true;
  if (worst > best_worst) std::copy(best, best + count, x);
  return false;
}

}  // namespace kodawari::rod
