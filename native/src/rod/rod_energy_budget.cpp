// The rod solver's energy budget (docs/algorithms.md §3.3, "Energy budget"): an energy
// projection in the manner of Dinev, Liu & Kavan (2018, "Stabilizing integrators for real-time
// physics") and Su, Sheth & Fedkiw (2013, "Energy conservation for the simulation of deformable
// bodies"). Every window of 1/24 s of simulated time, the state the window began with, carried
// rigidly along by the root's motion over it (that motion is the input), sets the energy the
// window may end with, measured relative to the root's rigid motion. If the substeps ended above
// it, the joints' motion relative to the root is scaled down; only if position and shape alone
// are above it do the joints move: down the potential's gradient, or back towards the carried
// start state.
#include <algorithm>
#include <cmath>
#include <limits>

#include "rod_detail.hpp"

namespace kodawari::rod::detail {

namespace {

// Bisection steps of the line search on positions: the fraction kept is resolved to 1/256.
constexpr int kLineSearchSteps = 8;

// -½ Σ |Ω × (x_j - o)|²: the centrifugal part of chain_kinetic, what it is at zero relative motion.
Real centrifugal(std::size_t count, const Vec3* x, const RigidMotion& frame) {
  Real sum = 0;
  if (frame.spin.squaredNorm() == 0) return sum;
  for (std::size_t j = 2; j < count; ++j) sum -= Real(0.5) * frame.spin.cross(x[j] - frame.origin).squaredNorm();
  return sum;
}

// The root's rigid velocity at x.
Vec3 carried_velocity(const RigidMotion& frame, const Vec3& x) {
  return frame.velocity + frame.spin.cross(x - frame.origin);
}

// Lengths restored joint by joint from the (kinematic) root: the trial moves are small, so this
// moves joints by second-order amounts.
void restore_lengths(std::size_t count, Vec3* x, const Real* lengths) {
  for (std::size_t j = 2; j < count; ++j) {
    const Vec3 d = x[j] - x[j - 1];
    const Real len = d.norm();
    if (len > 1e-12) x[j] = x[j - 1] + d * (lengths[j - 2] / len);
  }
}

// The potential (gravity, shape matching and the centrifugal term) of a trial state.
Real trial_potential(std::size_t count, const Vec3* x, const Quat* q, const Vec3* x_rest, const Quat* q_rest, Real e,
                     Real kappa, const Vec3& g, const RigidMotion& frame, const Quat* guesses) {
  Real gravitational = 0, shape = 0;
  chain_potential(count, x, q, x_rest, q_rest, e, kappa, g, gravitational, shape, nullptr, nullptr, guesses);
  return gravitational + shape + centrifugal(count, x, frame);
}

// The least move of the positions that brings the potential down to `level`: a Newton step on
// the excess along the potential's gradient, ∇V_j = -(κ/3) pull_j - g + Ω × (Ω × r_j), by
// ΔV / |∇V|² (Dinev et al. 2018 project onto the energy level along its gradient; positions
// only), doubled up to three times until it gets there. `pull` as chain_potential fills it.
// Returns the potential reached, or NaN when it did not get there.
Real level_by_newton(std::size_t count, RodState& s, const Vec3* x_rest, const Quat* q_rest, const Real* lengths,
                     Real e, Real kappa, const Vec3& g, Real level, Real excess, const RigidMotion& frame,
                     const Vec3List& pull, Vec3List& x_trial, const Quat* guesses) {
  const Real missed = std::numeric_limits<Real>::quiet_NaN();
  thread_local Vec3List gradient;
  gradient.resize(count);
  Real norm2 = 0;
  for (std::size_t j = 2; j < count; ++j) {
    gradient[j] = -(kappa / 3) * pull[j] - g + frame.spin.cross(frame.spin.cross(s.x[j] - frame.origin));
    norm2 += gradient[j].squaredNorm();
  }
  if (!(norm2 > 0) || !(excess > 0)) return missed;
  x_trial.resize(count);
  for (Real t = excess / norm2; t <= 8 * excess / norm2; t *= 2) {
    x_trial[0] = s.x[0];
    x_trial[1] = s.x[1];
    for (std::size_t j = 2; j < count; ++j) x_trial[j] = s.x[j] - t * gradient[j];
    restore_lengths(count, x_trial.data(), lengths);
    const Real trial = trial_potential(count, x_trial.data(), s.q.data(), x_rest, q_rest, e, kappa, g, frame, guesses);
    if (trial <= level) {
      for (std::size_t j = 2; j < count; ++j) s.x[j] = x_trial[j];
      return trial;
    }
  }
  return missed;
}

// Position and shape alone are over the budget: first the least move along the potential's
// gradient (level_by_newton); failing that, descend it in larger steps: each joint moves a
// fraction φ of the way to the average of its groups' goals plus φ g / κ, each orientation a
// fraction φ towards its groups' R q̄, the smallest φ of 1/64 ... 1 that gets within the budget.
// If none does, the joints go back towards the carried start state (within the budget by
// construction) by the largest fraction that keeps them within, found by bisection. Returns the
// potential of the state kept.
Real hold_potential(std::size_t count, RodState& s, const Vec3* x_rest, const Quat* q_rest, const Real* lengths, Real e,
                    Real kappa, const Vec3& g, const EnergyBudget& budget, const Vec3List& x_carried,
                    const QuatList& q_carried, Vec3List& x_trial, QuatList& q_trial, bool& reverted,
                    const Quat* guesses) {
  reverted = false;
  const RigidMotion& frame = budget.motion;
  x_trial.resize(count);
  q_trial.resize(count);
  thread_local Vec3List pull;
  thread_local std::vector<Eigen::Matrix<Real, 4, 1>, Eigen::aligned_allocator<Eigen::Matrix<Real, 4, 1>>> turn;
  pull.resize(count);
  turn.resize(count);
  Real gravitational = 0, shape = 0;
  chain_potential(count, s.x.data(), s.q.data(), x_rest, q_rest, e, kappa, g, gravitational, shape, pull.data(),
                  turn.data(), guesses);
  const Real excess = gravitational + shape + centrifugal(count, s.x.data(), frame) - budget.energy;
  const Real levelled =
      level_by_newton(count, s, x_rest, q_rest, lengths, e, kappa, g, budget.energy, excess, frame, pull, x_trial,
                      guesses);
  if (!std::isnan(levelled)) return levelled;
  const Vec3 sag = g / kappa;
  for (Real phi = Real(1) / 64; phi <= 1; phi *= 2) {
    x_trial[0] = s.x[0];
    x_trial[1] = s.x[1];
    q_trial[0] = s.q[0];
    for (std::size_t j = 2; j < count; ++j) x_trial[j] = s.x[j] + phi * (pull[j] / 3 + sag);
    for (std::size_t j = 1; j < count; ++j) {
      const Real norm = turn[j].norm();
      if (norm < 1e-12) {
        q_trial[j] = s.q[j];
        continue;
      }
      const Real groups = j + 1 < count ? Real(3) : Real(2);
      const Real f = phi * groups / 3;
      q_trial[j] = unit(Quat((1 - f) * s.q[j].coeffs() + (f / norm) * turn[j]));
    }
    restore_lengths(count, x_trial.data(), lengths);
    const Real trial =
        trial_potential(count, x_trial.data(), q_trial.data(), x_rest, q_rest, e, kappa, g, frame, guesses);
    if (trial <= budget.energy) {
      for (std::size_t j = 2; j < count; ++j) s.x[j] = x_trial[j];
      for (std::size_t j = 1; j < count; ++j) s.q[j] = q_trial[j];
      return trial;
    }
  }
  Real inside = 0, outside = 1, kept = 0;
  for (int step = 0; step <= kLineSearchSteps; ++step) {
    const Real f = step == kLineSearchSteps ? inside : (inside + outside) / 2;
    x_trial[0] = s.x[0];
    x_trial[1] = s.x[1];
    q_trial[0] = s.q[0];
    for (std::size_t j = 1; j < count; ++j) {
      const Real sign = q_carried[j].dot(s.q[j]) < 0 ? Real(-1) : Real(1);
      q_trial[j] = unit(Quat((1 - f) * q_carried[j].coeffs() + (sign * f) * s.q[j].coeffs()));
    }
    for (std::size_t j = 2; j < count; ++j) x_trial[j] = x_carried[j] + f * (s.x[j] - x_carried[j]);
    restore_lengths(count, x_trial.data(), lengths);
    const Real trial =
        trial_potential(count, x_trial.data(), q_trial.data(), x_rest, q_rest, e, kappa, g, frame, guesses);
    if (step == kLineSearchSteps) {
      kept = trial;
      break;
    }
    if (trial <= budget.energy) {
      inside = f;
    } else {
      outside = f;
    }
  }
  for (std::size_t j = 2; j < count; ++j) s.x[j] = x_trial[j];
  for (std::size_t j = 1; j < count; ++j) s.q[j] = q_trial[j];
  reverted = inside == 0;
  return kept;
}

}  // namespace

void open_energy_window(std::size_t count, RodState& s, const Vec3& origin, const Quat& rotation, Real shape,
                        const Vec3& gravity, bool asleep, int phase) {
  EnergyWindow& w = s.window;
  w.steps = phase;
  w.first = phase;
  w.reopen = false;
  w.asleep = asleep;
  w.gravity = gravity;
  w.origin = origin;
  w.rotation = rotation;
  w.x.assign(s.x.begin(), s.x.end());
  w.q.assign(s.q.begin(), s.q.end());
  w.speed2 = 0;
  w.spin2 = 0;
  w.momentum.setZero();
  w.angular.setZero();
  w.spin.setZero();
  for (std::size_t j = 2; j < count; ++j) {
    w.speed2 += s.v[j].squaredNorm();
    w.momentum += s.v[j];
    w.angular += (s.x[j] - origin).cross(s.v[j]);
  }
  for (std::size_t j = 1; j < count; ++j) {
    w.spin2 += s.omega[j].squaredNorm();
    w.spin += s.omega[j];
  }
  w.shape = shape;
}

Real close_energy_window(std::size_t count, RodState& s, const Vec3* x_rest, const Quat* q_rest, const Real* lengths,
                         Real e, Real kappa, const Vec3& g, const Vec3& origin, const Quat& rotation, Real duration,
                         const std::vector<Collider>& colliders, Real radius, const Quat* guesses,
                         BudgetScratch& scratch, bool& rests) {
  rests = false;
  const EnergyWindow& w = s.window;
  // The root's rigid motion over the window: velocity V and spin Ω, constant.
  Quat turn = (rotation * w.rotation.conjugate()).normalized();
  if (turn.w() < 0) turn.coeffs() = -turn.coeffs();
  const Real sine = turn.vec().norm();
  EnergyBudget budget;
  budget.motion.origin = origin;
  budget.motion.velocity = (origin - w.origin) / duration;
  budget.motion.spin =
      sine > 1e-12 ? Vec3(turn.vec() * (2 * std::atan2(sine, turn.w()) / (sine * duration))) : Vec3::Zero();
  const Vec3& V = budget.motion.velocity;
  const Vec3& spin = budget.motion.spin;
  // The budget: the kinetic energy the window began with, relative to that motion (chain_kinetic
  // expanded in the moments kept, r_j = x_j - o at the start:
  //   ½ Σ|v - V|² - Ω · Σ r × (v - V) + e Σ |ω - Ω|²),
  // plus the gravity and shape of the start state carried rigidly by the root to the end (the
  // shape energy is unchanged by a rigid motion).
  const Real joints = Real(count - 2), particles = Real(count - 1);
  Vec3 offsets = Vec3::Zero();
  for (std::size_t j = 2; j < count; ++j) offsets += w.x[j] - w.origin;
  const Real kinetic = Real(0.5) * w.speed2 - V.dot(w.momentum) + Real(0.5) * joints * V.squaredNorm() -
                       spin.dot(w.angular - offsets.cross(V)) +
                       e * (w.spin2 - 2 * spin.dot(w.spin) + particles * spin.squaredNorm());
  scratch.x_carried.resize(count);
  scratch.q_carried.resize(count);
  Real gravitational = 0;
  for (std::size_t j = 2; j < count; ++j) {
    scratch.x_carried[j] = origin + turn * (w.x[j] - w.origin);
    scratch.q_carried[j] = (turn * w.q[j]).normalized();
    gravitational -= g.dot(scratch.x_carried[j]);
  }
  scratch.x_carried[0] = s.x[0];
  scratch.q_carried[0] = s.q[0];
  scratch.x_carried[1] = s.x[1];
  scratch.q_carried[1] = (turn * w.q[1]).normalized();
  budget.energy = kinetic + gravitational + w.shape;

  // The state now, relative to the same motion.
  const RigidMotion& frame = budget.motion;
  Real now_gravitational = 0, shape = 0;
  chain_potential(count, s.x.data(), s.q.data(), x_rest, q_rest, e, kappa, g, now_gravitational, shape, nullptr,
                  nullptr, guesses);
  const Real now_kinetic = chain_kinetic(count, s.x.data(), s.v.data(), s.omega.data(), e, frame);
  if (now_kinetic + now_gravitational + shape <= budget.energy) return shape;

  Real potential = now_gravitational + shape + centrifugal(count, s.x.data(), frame);
  bool moved = false, reverted = false;
  if (potential > budget.energy) {
    potential = hold_potential(count, s, x_rest, q_rest, lengths, e, kappa, g, budget, scratch.x_carried,
                               scratch.q_carried, scratch.x_trial, scratch.q_trial, reverted, guesses);
    moved = true;
    // Put back where the window began with the root still: the chain rests (EnergyWindow::asleep).
    rests = reverted && budget.motion.velocity.squaredNorm() == 0 && budget.motion.spin.squaredNorm() == 0;
    // A move towards the rest shape may enter a collider: out again, joint by joint from the
    // root on its bone length, as the solver's last pass does (contact is exempt from the
    // budget, like the solver's own push-out).
    if (!colliders.empty()) {
      bool pushed = false;
      for (std::size_t j = 2; j < count; ++j) {
        for (int pass = 0; pass < 4; ++pass) {
          const Vec3 d = s.x[j] - s.x[j - 1];
          const Real len = d.norm();
          if (pass > 0 && len > 1e-12) s.x[j] = s.x[j - 1] + d * (lengths[j - 2] / len);
          if (!push_out_of_colliders(s.x[j], colliders, radius)) break;
          pushed = true;
          rests = false;
        }
      }
      if (pushed) {
        potential = trial_potential(count, s.x.data(), s.q.data(), x_rest, q_rest, e, kappa, g, frame, guesses);
      }
    }
  }
  // Scale the joints' motion relative to the root so the kinetic energy fills what is left.
  // After a move of the positions the solver's velocities no longer belong to them (the step
  // they came from was refused): the joints keep only the root's motion. Kept, they re-created
  // the same refused step window after window and stiff strands buzzed at 1-2 cm/s for ever.
  Real relative = 0;
  for (std::size_t j = 2; j < count; ++j) {
    relative += Real(0.5) * (s.v[j] - carried_velocity(frame, s.x[j])).squaredNorm();
  }
  for (std::size_t j = 1; j < count; ++j) relative += e * (s.omega[j] - frame.spin).squaredNorm();
  const Real room = budget.energy - potential;
  const Real scale = moved || !(room > 0 && relative > 0) ? Real(0) : std::min(Real(1), std::sqrt(room / relative));
  for (std::size_t j = 2; j < count; ++j) {
    const Vec3 u = carried_velocity(frame, s.x[j]);
    s.v[j] = u + scale * (s.v[j] - u);
  }
  for (std::size_t j = 1; j < count; ++j) s.omega[j] = frame.spin + scale * (s.omega[j] - frame.spin);
  if (moved) {
    chain_potential(count, s.x.data(), s.q.data(), x_rest, q_rest, e, kappa, g, now_gravitational, shape, nullptr,
                    nullptr, guesses);
  }
  return shape;
}

}  // namespace kodawari::rod::detail
