#include "kodawari/gait/ccd_ik.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::gait {

namespace {
constexpr int kMaxBones = 6;

Real cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// sin and cos of a CCD step: a Taylor series for the usual small turns (error < 4e-7
// below 0.8 rad), libm beyond. The pose is rebuilt from the angles after the sweeps,
// so this only steers the iteration.
void small_sincos(Real x, Real& c, Real& s) {
  if (std::abs(x) > 0.8) {
    c = std::cos(x);
    s = std::sin(x);
    return;
  }
  const Real x2 = x * x;
  s = x * (1 - x2 / 6 * (1 - x2 / 20 * (1 - x2 / 42 * (1 - x2 / 72))));
  c = 1 - x2 / 2 * (1 - x2 / 12 * (1 - x2 / 30 * (1 - x2 / 56)));
}

// atan2 to ~1e-5 rad at a fraction of libm's cost: CCD only needs the turn roughly,
// since every joint then turns by exactly the (clamped) angle it records.
Real fast_atan2(Real y, Real x) {
  const Real ax = std::abs(x), ay = std::abs(y);
  const Real big = std::max(ax, ay);
  if (big == 0) return 0;
  const Real a = std::min(ax, ay) / big;
  const Real s = a * a;
  Real r = ((((-0.0117212 * s + 0.05265332) * s - 0.11643287) * s + 0.19354346) * s - 0.33262347) * s + 0.99997726;
  r *= a;
  if (ay > ax) r = kPi / 2 - r;
  if (x < 0) r = kPi - r;
  return y < 0 ? -r : r;
}
}  // namespace

Real LegChain::length() const {
  Real total = 0;
  for (Real l : lengths) total += l;
  return total;
}

void chain_points(const LegChain& chain, const Real* angles, Vec2* points) {
  points[0] = chain.root;
  Real turned = 0;
  for (int k = 0; k < chain.size(); ++k) {
    turned += angles[k];
    // Positive pose angles turn clockwise in (f, u): see LegChain.
    const Real direction = chain.rest_direction[k] - turned;
    points[k + 1] = points[k] + chain.lengths[k] * Vec2(std::cos(direction), std::sin(direction));
  }
}

Vec2 chain_foot(const LegChain& chain, const Real* angles) {
  Vec2 points[kMaxBones + 1];
  chain_points(chain, angles, points);
  return points[chain.size()];
}

namespace {
// `iterations` sweeps of CCD from the last bone up; each joint takes `share` of the
// turn that points the line joint -> foot at the target, then is clamped.
CcdResult ccd_sweeps(const LegChain& chain, const Vec2& target, int iterations, Real tolerance, bool use_stiffness,
                     Real* angles) {
  const int n = chain.size();
  Vec2 points[kMaxBones + 1];
  chain_points(chain, angles, points);
  CcdResult result;
  result.error = (points[n] - target).norm();
  for (int it = 0; it < iterations && result.error > tolerance; ++it) {
    for (int k = n - 1; k >= 0; --k) {
      const Vec2 to_foot = points[n] - points[k];
      const Vec2 to_target = target - points[k];
      if (to_foot.squaredNorm() < 1e-18 || to_target.squaredNorm() < 1e-18) continue;
      const Real turn_ccw = fast_atan2(cross2(to_foot, to_target), to_foot.dot(to_target));
      const Real share = use_stiffness ? chain.stiffness[k] : Real(1);
      const Real clamped = std::clamp(angles[k] - share * turn_ccw, chain.limit_min[k], chain.limit_max[k]);
      const Real applied = clamped - angles[k];
      if (applied == 0) continue;
      angles[k] = clamped;
      // Rotate the points below joint k about it (clockwise by `applied`).
      Real c, s;
      small_sincos(applied, c, s);
      for (int j = k + 1; j <= n; ++j) {
        const Vec2 d = points[j] - points[k];
        points[j] = points[k] + Vec2(c * d.x() + s * d.y(), -s * d.x() + c * d.y());
      }
    }
    const Real previous = result.error;
    result.error = (points[n] - target).norm();
    result.iterations = it + 1;
    if (result.error > previous * 0.999) break;  // stalled: limits hold it, more sweeps will not help
  }
  chain_points(chain, angles, points);
  result.error = (points[n] - target).norm();
  return result;
}
}  // namespace

CcdResult solve_ccd(const LegChain& chain, const Vec2& target, int iterations, Real tolerance, Real* angles,
                    bool allow_restart) {
  const int n = chain.size();
  for (int k = 0; k < n; ++k) {
    angles[k] = std::isfinite(angles[k]) ? std::clamp(angles[k], chain.limit_min[k], chain.limit_max[k])
                                         : std::clamp(Real(0), chain.limit_min[k], chain.limit_max[k]);
  }
  // The seed's CCD with joint stiffness shapes the pose (the femur leads, not the hoof).
  CcdResult result = ccd_sweeps(chain, target, iterations, tolerance, true, angles);
  if (result.error <= tolerance) return result;
  // Stiffness slows convergence; when it stalls, plain CCD closes the remaining gap
  // from that pose, so a reachable planted foot is really reached.
  Real polished[kMaxBones];
  std::copy(angles, angles + n, polished);
  CcdResult polish = ccd_sweeps(chain, target, iterations, tolerance, false, polished);
  polish.iterations += result.iterations;
  if (polish.error < result.error) {
    std::copy(polished, polished + n, angles);
    result = polish;
  }
  if (result.error <= tolerance || !allow_restart) return result;
  // A warm start can sit in a corner of the limits; cold starts from the rest pose and
  // from the middle of the limits find the other branches. Keep whichever lands
  // closest: the foot then moves by at most the warm start's miss.
  const std::vector<Real> warm(angles, angles + n);
  for (int seed = 0; allow_restart && seed < 3 && result.error > std::max(tolerance, Real(1e-3)); ++seed) {
    Real cold[kMaxBones];
    for (int k = 0; k < n; ++k) {
      const Real middle = (chain.limit_min[k] + chain.limit_max[k]) / 2;
      const bool at_limit = warm[k] <= chain.limit_min[k] + 1e-6 || warm[k] >= chain.limit_max[k] - 1e-6;
      if (seed == 0) cold[k] = at_limit ? middle : warm[k];  // free the joints stuck on a limit
      else if (seed == 1) cold[k] = std::clamp(Real(0), chain.limit_min[k], chain.limit_max[k]);
      else cold[k] = middle;
    }
    CcdResult again = ccd_sweeps(chain, target, iterations, tolerance, true, cold);
    if (again.error > tolerance) again = ccd_sweeps(chain, target, iterations, tolerance, false, cold);
    if (again.error < result.error - 1e-4) {
      std::copy(cold, cold + n, angles);
      again.iterations += result.iterations;
      result = again;
    }
  }
  return result;
}

CcdResult solve_dls(const LegChain& chain, const Vec2& target, int iterations, Real tolerance, Real* angles,
                    bool soften) {
  const int n = chain.size();
  for (int k = 0; k < n; ++k) {
    angles[k] = std::isfinite(angles[k]) ? std::clamp(angles[k], chain.limit_min[k], chain.limit_max[k])
                                         : std::clamp(Real(0), chain.limit_min[k], chain.limit_max[k]);
  }
  const Real damping = 1e-3 * chain.length();
  Vec2 points[kMaxBones + 1];
  CcdResult result;
  chain_points(chain, angles, points);
  result.error = (points[n] - target).norm();
  for (int it = 0; it < iterations && result.error > tolerance; ++it) {
    const Vec2 e = target - points[n];
    Vec2 jac[kMaxBones];
    for (int k = 0; k < n; ++k) {
      const Vec2 r = points[n] - points[k];
      jac[k] = Vec2(r.y(), -r.x());  // d foot / d theta_k: positive theta turns clockwise
    }
    // The step over the free joints, each weighted by its stiffness and, near the limit
    // it turns towards, less and less (weighted least norm, Chan & Dubey 1995): a joint
    // slows into its limit and the others take over gradually, not in one frame.
    // A joint on a limit that the step would push past it is held for this step and the
    // step is taken again without it (an active set).
    bool held[kMaxBones] = {};
    Real soft[kMaxBones];
    Real step[kMaxBones];
    for (int k = 0; k < n; ++k) soft[k] = 1;
    for (int pass = 0; pass <= n + 1; ++pass) {
      Real a00 = damping * damping, a01 = 0, a11 = damping * damping;
      for (int k = 0; k < n; ++k) {
        if (held[k]) continue;
        const Real w = chain.stiffness[k] * soft[k];
        a00 += w * jac[k].x() * jac[k].x();
        a01 += w * jac[k].x() * jac[k].y();
        a11 += w * jac[k].y() * jac[k].y();
      }
      const Real det = a00 * a11 - a01 * a01;
      const Vec2 y = det > 0 ? Vec2((a11 * e.x() - a01 * e.y()) / det, (a00 * e.y() - a01 * e.x()) / det)
                             : Vec2::Zero();
      bool changed = false;
      for (int k = 0; k < n; ++k) {
        step[k] = held[k] ? 0 : chain.stiffness[k] * soft[k] * y.dot(jac[k]);
        const bool at_min = angles[k] <= chain.limit_min[k] + 1e-9 && step[k] < 0;
        const bool at_max = angles[k] >= chain.limit_max[k] - 1e-9 && step[k] > 0;
        if (!held[k] && (at_min || at_max)) changed = held[k] = true;
      }
      if (pass == 0 && soften) {  // soften the joints turning into a limit, from the first step's direction
        for (int k = 0; k < n; ++k) {
          const Real room = step[k] > 0 ? chain.limit_max[k] - angles[k] : angles[k] - chain.limit_min[k];
          const Real margin = std::min(Real(0.35), (chain.limit_max[k] - chain.limit_min[k]) / 4);
          const Real f = margin > 0 ? std::clamp(room / margin, Real(0.05), Real(1)) : Real(1);
          soft[k] = f * f;
        }
        changed = true;
      }
      if (!changed) break;
    }
    Real largest = 0;
    for (int k = 0; k < n; ++k) largest = std::max(largest, std::abs(step[k]));
    if (largest == 0) break;
    const Real scale = largest > 0.2 ? 0.2 / largest : 1;  // small steps: the linearisation holds
    for (int k = 0; k < n; ++k) {
      angles[k] = std::clamp(angles[k] + scale * step[k], chain.limit_min[k], chain.limit_max[k]);
    }
    chain_points(chain, angles, points);
    const Real previous = result.error;
    result.error = (points[n] - target).norm();
    result.iterations = it + 1;
    if (result.error > previous * 0.9999 && scale == 1) break;  // stalled
  }
  return result;
}

Real directional_reach(const LegChain& chain, const Vec2& direction) {
  std::vector<Real> angles(chain.size());
  for (int k = 0; k < chain.size(); ++k) angles[k] = std::clamp(Real(0), chain.limit_min[k], chain.limit_max[k]);
  const Vec2 far = chain.root + direction * (4 * chain.length());
  solve_ccd(chain, far, 64, 0, angles.data());
  return std::max(Real(0), (chain_foot(chain, angles.data()) - chain.root).dot(direction));
}

}  // namespace kodawari::gait
