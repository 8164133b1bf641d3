// A stance's joint motion evened out over its frames (docs/algorithms.md §4.8, "The
// fastest joint of a stance"): the whole stance solved at once for the least largest
// change of any joint between frames, the planted foot held at every frame.
#include <cmath>

#include <Eigen/Dense>

#include "stance_even.hpp"

namespace kodawari::gait::stages {

namespace {

using MatX = Eigen::Matrix<Real, Eigen::Dynamic, Eigen::Dynamic>;
using VecX = Eigen::Matrix<Real, Eigen::Dynamic, 1>;

// Outer iterations: each reweights the changes and takes one constrained Gauss-Newton step.
// The norm's exponent rises over the first half of them from a plain least squares
// smoothing (p = 2, a geodesic-like path) towards the largest change (p large: Lawson's
// reweighting), and stays there.
constexpr int kRounds = 40;
constexpr Real kLargestStep = 0.1;    // rad: one round moves no joint further
constexpr int kHalvings = 5;          // of a step that does not lower the norm
constexpr Real kFloorChange = 1e-4;   // rad: changes below this weigh as this
constexpr Real kWeightFloor = 1e-3;   // the least weight of a change (the largest weighs 1)
constexpr Real kProximal = 0.05;      // step damping, against the largest change's weight (1)

// Solves the tridiagonal system (d on the diagonal, o[i] joining i and i+1) for rhs in
// place (Thomas algorithm; the matrix is symmetric and diagonally dominant).
void solve_tridiagonal(const std::vector<Real>& d, const std::vector<Real>& o, Real* rhs, int count) {
  std::vector<Real> c(count), diag(count);
  diag[0] = d[0];
  for (int i = 1; i < count; ++i) {
    c[i - 1] = o[i - 1] / diag[i - 1];
    diag[i] = d[i] - c[i - 1] * o[i - 1];
    rhs[i] -= c[i - 1] * rhs[i - 1];
  }
  rhs[count - 1] /= diag[count - 1];
  for (int i = count - 2; i >= 0; --i) rhs[i] = (rhs[i] - o[i] * rhs[i + 1]) / diag[i];
}

}  // namespace

bool even_stance(const LegChain& chain, const Vec2d* goals, int count, const Real* before, const Real* after,
                 const std::vector<char>& counted, std::vector<Real>& angles, std::vector<Real>& errors,
                 Real tolerance, const std::vector<Real>& allowed, int iterations, Real last_exponent) {
  const int n = chain.size();
  if (count < 2) return false;
  const int changes = after ? count + 1 : count;  // change j goes into frame j (count: into `after`)
  std::vector<Real> theta = angles, best, best_error, trial_error(count);
  auto at = [&](const std::vector<Real>& pose, int i, int b) -> Real {  // with the fixed neighbours
    return i < 0 ? before[b] : i >= count ? after[b] : pose[i * n + b];
  };
  // The largest counted change and the largest other one (which may not grow).
  auto largest = [&](const std::vector<Real>& pose, bool of_counted) {
    Real top = 0;
    for (int j = 0; j < changes; ++j) {
      if (static_cast<bool>(counted[j]) != of_counted) continue;
      for (int b = 0; b < n; ++b) top = std::max(top, std::abs(at(pose, j, b) - at(pose, j - 1, b)));
    }
    return top;
  };
  const Real counted_top = std::max(kFloorChange, largest(angles, true));
  const Real other_top = std::max(counted_top, largest(angles, false));
  Real best_turn = counted_top;
  // Each change measured against its group's largest at the start: the counted changes'
  // peak is what is lowered, the others only kept from growing past theirs.
  auto scaled = [&](const std::vector<Real>& pose, int j, int b) {
    return std::abs(at(pose, j, b) - at(pose, j - 1, b)) / (counted[j] ? counted_top : other_top);
  };
  auto pnorm = [&](const std::vector<Real>& pose, Real p) {
    Real top = kFloorChange / counted_top, sum = 0;
    for (int j = 0; j < changes; ++j) {
      for (int b = 0; b < n; ++b) top = std::max(top, scaled(pose, j, b));
    }
    for (int j = 0; j < changes; ++j) {
      for (int b = 0; b < n; ++b) sum += std::pow(scaled(pose, j, b) / top, p);
    }
    return top * std::pow(sum, 1 / p);
  };
  std::vector<Real> weight(static_cast<std::size_t>(changes) * n), diag(count), off(count), g(count), unit(count);
  MatX jac(2 * count, n);  // each frame's 2 x n Jacobian, stacked
  VecX miss(2 * count);
  std::vector<Real> hinv_g(static_cast<std::size_t>(count) * n), step(static_cast<std::size_t>(count) * n);
  std::vector<MatX> hinv(n, MatX(count, count));
  Vec2 points[kMaxBones + 1];
  for (int round = 0; round < kRounds; ++round) {
    const Real p = 2 + (last_exponent - 2) * std::min(Real(1), Real(round) / (kRounds / 2));
    Real top = kFloorChange / counted_top;
    for (int j = 0; j < changes; ++j) {
      for (int b = 0; b < n; ++b) top = std::max(top, scaled(theta, j, b));
    }
    // Lawson's weights |change|^(p-2), against the largest so they stay finite.
    for (int j = 0; j < changes; ++j) {
      const Real unit_scale = counted[j] ? counted_top : other_top;
      for (int b = 0; b < n; ++b) {
        const Real change = std::max(kFloorChange / unit_scale, scaled(theta, j, b));
        weight[j * n + b] = (std::pow(change / top, p - 2) + kWeightFloor) / (unit_scale * unit_scale);
      }
    }
    Real wmax = 0;
    for (Real w : weight) wmax = std::max(wmax, w);
    for (Real& w : weight) w /= wmax;
    for (int i = 0; i < count; ++i) {
      chain_points(chain, theta.data() + i * n, points);
      miss.segment<2>(2 * i) = goals[i] - points[n];
      for (int b = 0; b < n; ++b) {
        const Vec2 r = points[n] - points[b];
        jac(2 * i, b) = r.y();
        jac(2 * i + 1, b) = -r.x();
      }
    }
    // Per joint, the smoothing's Hessian is tridiagonal over the frames (plus a proximal
    // term that keeps each step short): its inverse, and its solve for the gradient.
    for (int b = 0; b < n; ++b) {
      for (int i = 0; i < count; ++i) {
        diag[i] = weight[i * n + b] + (i + 1 < changes ? weight[(i + 1) * n + b] : 0) + kProximal;
        off[i] = i + 1 < count ? -weight[(i + 1) * n + b] : 0;
        g[i] = weight[i * n + b] * (at(theta, i, b) - at(theta, i - 1, b)) -
               (i + 1 < changes ? weight[(i + 1) * n + b] * (at(theta, i + 1, b) - at(theta, i, b)) : 0);
      }
      solve_tridiagonal(diag, off, g.data(), count);
      for (int i = 0; i < count; ++i) hinv_g[i * n + b] = g[i];
      for (int col = 0; col < count; ++col) {
        std::fill(unit.begin(), unit.end(), Real(0));
        unit[col] = 1;
        solve_tridiagonal(diag, off, unit.data(), count);
        for (int i = 0; i < count; ++i) hinv[b](i, col) = unit[i];
      }
    }
    // The step d minimises 1/2 d'Hd + g'd with each frame's foot moved onto its goal to
    // first order (J_i d_i = e_i): d = H^-1 (A' l - g), (A H^-1 A') l = e + A H^-1 g.
    MatX schur = MatX::Zero(2 * count, 2 * count);
    VecX rhs = miss;
    for (int i = 0; i < count; ++i) {
      for (int r = 0; r < 2; ++r) {
        for (int b = 0; b < n; ++b) rhs(2 * i + r) += jac(2 * i + r, b) * hinv_g[i * n + b];
        for (int j = 0; j < count; ++j) {
          for (int s = 0; s < 2; ++s) {
            Real sum = 0;
            for (int b = 0; b < n; ++b) sum += jac(2 * i + r, b) * hinv[b](i, j) * jac(2 * j + s, b);
            schur(2 * i + r, 2 * j + s) = sum;
          }
        }
      }
    }
    schur.diagonal().array() += 1e-12;
    const VecX lambda = schur.ldlt().solve(rhs);
    Real longest = 0;
    for (int b = 0; b < n; ++b) {
      for (int i = 0; i < count; ++i) {
        Real sum = 0;
        for (int j = 0; j < count; ++j) {
          sum += hinv[b](i, j) * (jac(2 * j, b) * lambda(2 * j) + jac(2 * j + 1, b) * lambda(2 * j + 1));
        }
        step[i * n + b] = sum - hinv_g[i * n + b];
        longest = std::max(longest, std::abs(step[i * n + b]));
      }
    }
    // Backtracking: the step, then half of it and so on, until the p-norm of the changes
    // falls with every foot back on its goal (the step holds them only to first order).
    const std::vector<Real> from = theta;
    const Real now = pnorm(theta, p);
    Real scale = longest > kLargestStep ? kLargestStep / longest : 1;
    bool improved = false;
    for (int half = 0; half < kHalvings && !improved; ++half, scale /= 2) {
      bool held = true;
      for (int i = 0; i < count && held; ++i) {
        for (int b = 0; b < n; ++b) {
          theta[i * n + b] =
              std::clamp(from[i * n + b] + scale * step[i * n + b], chain.limit_min[b], chain.limit_max[b]);
        }
        trial_error[i] = solve_dls(chain, goals[i], iterations, tolerance, theta.data() + i * n).error;
        held = trial_error[i] <= std::max(errors[i], allowed[i]);
      }
      improved = held && pnorm(theta, p) < now;
    }
    if (!improved) {
      theta = from;
      if (p >= last_exponent) break;  // settled at the last exponent
      continue;                       // a larger exponent may still move
    }
    const Real turn = largest(theta, true);
    if (turn < best_turn && largest(theta, false) <= other_top) {
      best_turn = turn;
      best = theta;
      best_error = trial_error;
    }
  }
  if (best.empty()) return false;
  angles.swap(best);
  errors.swap(best_error);
  return true;
}

}  // namespace kodawari::gait::stages
