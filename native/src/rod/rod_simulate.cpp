// One frame of one rod (docs/algorithms.md §3.3): substeps of oriented-particle shape
// matching (Müller & Chentanez 2011, "Solid simulation with oriented particles") with
// exact inextensibility (rod/inextensibility.hpp, Goldenthal et al. 2007), held to an energy
// budget every 1/24 s (rod_energy_budget.cpp).
#include "kodawari/rod/rod_system.hpp"

#include <algorithm>

#include <glm/gtc/noise.hpp>
#include <glm/vec2.hpp>

#include "kodawari/rod/inextensibility.hpp"
#include "rod_detail.hpp"

namespace kodawari::rod {

using namespace detail;

namespace {

// Per-thread work arrays of simulate(), reused from rod to rod and frame to frame:
// the substep loop allocates nothing.
struct SimulationScratch {
  Vec3List x_rest;
  QuatList q_rest, q_rest_conjugate, new_q;
  std::vector<Real> lengths, inverse_hits, inverse_mass, projection;
  // Per group c (members c-1, c, c+1 clipped to the chain): member weights w_i / mass,
  // rest offsets from the rest centroid r_i = x̄_i - c̄, and w_i r_i (so that
  // A = Σ w_i (x_i - c)(x̄_i - c̄)ᵀ = Σ x_i (w_i r_i)ᵀ, because Σ w_i r_i = 0).
  std::vector<Real> group_weights;   // 3 per group: w_i / mass
  std::vector<Real> group_ellipsoid; // 3 per group: w_i e (groups with a kinematic member)
  Vec3List group_rest, group_weighted_rest;  // 3 per group
  std::vector<Mat3, Eigen::aligned_allocator<Mat3>> orientation_terms;
  QuatList orientation_quats;
  Vec3List displacement;
  BudgetScratch budget;  // the energy budget's work arrays
};

SimulationScratch& simulation_scratch() {
  thread_local SimulationScratch scratch;
  return scratch;
}

// The rotation matrix of a unit quaternion (as Eigen's toRotationMatrix, inlined here).
inline Mat3 rotation_matrix(const Quat& q) {
  return q.toRotationMatrix();
}

}  // namespace

void RodSystem::simulate(std::size_t r, const FrameInput& input, const std::vector<Collider>& colliders) {
  const RodDefinition& rod = rods_[r];
  const RodParams& p = rod.params;
  RodState& s = states_[r];
  const std::size_t n = rod.bones.size();
  const std::size_t count = n + 2;

  // Kinematic anchor at the end of this frame.
  Quat parent_rotation;
  Vec3 parent_position;
  Mat3 parent_linear;
  bone_transform(input.bone_matrices, static_cast<std::size_t>(rod.parent_bone), parent_rotation, parent_position,
                 &parent_linear);
  const Vec3 anchor_end = parent_linear * rod.geometry.offsets[0] + parent_position;
  Quat anchor_end_rotation = (parent_rotation * rod.geometry.rest_rotations[0]).normalized();
  if (anchor_end_rotation.dot(s.anchor_rotation) < 0) anchor_end_rotation.coeffs() = -anchor_end_rotation.coeffs();
  const Vec3 anchor_start = s.anchor_position;
  const Quat anchor_start_rotation = s.anchor_rotation;

  // Fixed substep rate, independent of the scene's frame rate; leftover time carries over.
  const Real rate = kSubstepUnit * p.substeps;
  s.time_accumulator += std::max(input.frame_dt, Real(0));
  long steps = static_cast<long>(std::floor(s.time_accumulator * rate + 1e-9));
  s.time_accumulator = std::max(Real(0), s.time_accumulator - Real(steps) / rate);
  steps = std::min(steps, kMaxSubstepsPerFrame);

  // Everything below that depends only on the rest shape is computed once per frame.
  SimulationScratch& w = simulation_scratch();
  rest_particles(rod.geometry, s.rest_local, w.x_rest, w.q_rest);
  const Vec3List& x_rest = w.x_rest;
  const QuatList& q_rest = w.q_rest;
  w.q_rest_conjugate.resize(count);
  for (std::size_t j = 0; j < count; ++j) w.q_rest_conjugate[j] = q_rest[j].conjugate();
  w.lengths.resize(n);
  w.inverse_mass.assign(n + 1, Real(1));
  w.inverse_mass[0] = 0;  // the root joint is kinematic
  w.projection.resize(9 * (n + 1));
  for (std::size_t k = 0; k < n; ++k) w.lengths[k] = rod.geometry.segment_length(k);
  const Real ellipsoid = [&] {
    Real mean = 0;
    for (Real l : w.lengths) mean += l;
    mean /= Real(n);
    return (mean * mean) / 5;  // a sphere of radius one segment: a²/5
  }();
  // Particle j >= 2 belongs to the groups j-1, j and j+1 (those that exist): the Jacobi average.
  w.inverse_hits.assign(count, Real(0));
  for (std::size_t j = 2; j < count; ++j) w.inverse_hits[j] = Real(1) / Real(j + 1 < count ? 3 : 2);
  w.group_weights.assign(3 * count, Real(0));
  w.group_ellipsoid.assign(3 * count, Real(0));
  w.group_rest.assign(3 * count, Vec3::Zero());
  w.group_weighted_rest.assign(3 * count, Vec3::Zero());
  for (std::size_t c = 1; c < count; ++c) {
    const std::size_t lo = c - 1;
    const std::size_t members = std::min(c + 1, count - 1) - lo + 1;
    Real mass = 0;
    Vec3 c_rest = Vec3::Zero();
    for (std::size_t i = 0; i < members; ++i) {
      // Ghost and root are kinematic: heavier in the fit.
      const Real wi = (lo + i) <= 1 ? kKinematicWeight : Real(1);
      mass += wi;
      c_rest += wi * x_rest[lo + i];
      w.group_ellipsoid[3 * c + i] = wi * ellipsoid;
    }
    c_rest /= mass;
    for (std::size_t i = 0; i < members; ++i) {
      const Real wi = (lo + i) <= 1 ? kKinematicWeight : Real(1);
      w.group_weights[3 * c + i] = wi / mass;
      w.group_rest[3 * c + i] = x_rest[lo + i] - c_rest;
      w.group_weighted_rest[3 * c + i] = wi * w.group_rest[3 * c + i];
    }
  }

  const Mat3 world_to_armature = input.armature_matrix.block<3, 3>(0, 0).inverse();
  const Vec3 gravity = world_to_armature * (input.gravity * p.gravity);
  const Real base_dt = 1 / rate;
  const Real min_length = *std::min_element(w.lengths.begin(), w.lengths.end());
  // The root's velocity over this frame (the kinematic end of the first bone).
  const Real frame_time = steps > 0 ? Real(steps) * base_dt : Real(1);
  const Vec3 anchor_velocity = (anchor_end - anchor_start) / frame_time;

  // Energy budget (docs/algorithms.md §3.3, "Energy budget"): every 1/24 s of simulated time
  // (`substeps` base substeps, whatever the frame rate) the state may hold no more energy,
  // relative to the root's motion, than when that window began. Wind is an input the budget
  // does not account for: no budget while it blows.
  const bool budgeted = p.wind.squaredNorm() == 0;
  if (!budgeted) s.window.steps = -1;
  const Real kappa = shape_stiffness(p);

  w.orientation_terms.resize(count);
  w.orientation_quats.resize(count);
  w.displacement.resize(count);
  w.new_q.resize(count);
  Vec3* x = s.x.data();
  Quat* q = s.q.data();
  for (long step = 1; step <= steps; ++step) {
    if (budgeted && (s.window.steps < 0 || s.window.reopen)) {
      // A new window, or (the rest shape changed: its energy is input) a fresh start of the
      // current one that still ends where it would have, so windows close at the same simulated
      // times whatever the frame rate and however often the view changes the rest shape.
      Real gravitational = 0, shape = 0;
      chain_potential(count, x, q, w.x_rest.data(), w.q_rest.data(), ellipsoid, kappa, gravity, gravitational, shape);
      open_energy_window(count, s, x[1], q[0], shape, gravity, false, std::max(s.window.steps, 0));
    }
    if (budgeted && s.window.asleep) {
      // Asleep (EnergyWindow::asleep): skip this substep while nothing that could move the chain
      // has changed; any change wakes it, the window going on from the state it began with.
      const Real f = Real(step) / Real(steps);
      const Vec3 anchor = anchor_start + f * (anchor_end - anchor_start);
      const Quat anchor_rotation = anchor_start_rotation.slerp(f, anchor_end_rotation).normalized();
      bool still = (anchor - s.window.origin).squaredNorm() < Real(1e-24) &&
                   std::abs(std::abs(anchor_rotation.dot(s.window.rotation)) - 1) < Real(1e-12) &&
                   gravity == s.window.gravity;
      for (std::size_t j = 2; j < count && still && !colliders.empty(); ++j) {
        Vec3 probe = x[j];
        still = !push_out_of_colliders(probe, colliders, p.radius);
      }
      if (still) {
        if (++s.window.steps >= p.substeps) {  // the next window sleeps on
          s.window.steps = 0;
          s.window.first = 0;
        }
        continue;
      }
      s.window.asleep = false;
    }
    // No joint may move more than kMaxTravel bone lengths relative to the root in one
    // substep: beyond that the length projection's linearisation no longer sees the motion it
    // corrects (its corrections add up along the chain: on long chains of short bones a
    // whipping tip outruns it at the base rate). A chain carried along whole by the root
    // needs no split. Such substeps are split; the shape-matching fraction is rescaled so
    // the stiffness per base substep stays.
    Real fastest = 0;
    for (std::size_t j = 2; j < count; ++j) fastest = std::max(fastest, (s.v[j] - anchor_velocity).squaredNorm());
    const Real travel = (std::sqrt(fastest) + gravity.norm() * base_dt) * base_dt;
    // Gravity alone drops every joint by g dt² per substep while the root holds; the
    // projection lifts them all back through the root's bone, so that drop must stay a
    // small part of a bone (kMaxDrop), and the tension it builds along the chain, about
    // n g dt² at the root, must stay below half a bone (kMaxTension; §3.3).
    const Real drop = gravity.norm() * base_dt * base_dt;
    const Real split_needed =
        std::max({std::ceil(travel / (kMaxTravel * min_length)), std::ceil(std::sqrt(drop / (kMaxDrop * min_length))),
                  std::ceil(std::sqrt(Real(n) * drop / (kMaxTension * min_length)))});
    const int split = static_cast<int>(std::clamp(split_needed, Real(1), Real(kMaxSplit)));
    const Real dt = base_dt / Real(split);
    const Real inverse_dt = 1 / dt;
    const Real decay = std::exp(-p.damping * dt);
    const Real stiffness = split == 1 ? p.stiffness : Real(1) - std::pow(Real(1) - p.stiffness, Real(1) / Real(split));
    for (int sub = 1; sub <= split; ++sub) {
      const Real f = (Real(step - 1) + Real(sub) / Real(split)) / Real(steps);
      const Vec3 anchor = anchor_start + f * (anchor_end - anchor_start);
      const Quat anchor_rotation = anchor_start_rotation.slerp(f, anchor_end_rotation).normalized();
      x[0] = anchor + anchor_rotation * x_rest[0];
      q[0] = anchor_rotation;
      x[1] = anchor;

      // Wind with gusts: GLM Perlin noise over time, one noise line per rod (deterministic).
      const bool windy = p.wind.squaredNorm() > 0;
      Vec3 wind = Vec3::Zero();
      if (windy) {
        const Real t = input.time - (1 - f) * input.frame_dt;
        const Real gust = 1 + kGustAmount * Real(glm::perlin(glm::dvec2(t * kGustFrequency, 0.37 * Real(r) + 0.5)));
        wind = world_to_armature * (p.wind * gust);
      }

      // Predict.
      for (std::size_t j = 2; j < count; ++j) {
        Vec3 a = gravity;
        if (windy) a += kWindDrag * (wind - s.v[j]);
        s.v[j] = decay * s.v[j] + dt * a;
        s.prev_x[j] = x[j];
        x[j] += dt * s.v[j];
      }
      for (std::size_t j = 1; j < count; ++j) {
        s.omega[j] *= decay;
        s.prev_q[j] = q[j];
        q[j] = spin(q[j], s.omega[j] * dt);
      }

      for (int it = 0; it < p.iterations; ++it) {
        // Shape matching over each particle's neighbourhood {c-1, c, c+1} (Jacobi: averaged).
        // E_j = R(q_j) R(q̄_j)ᵀ = R(q_j q̄_j⁻¹); that quaternion also warm-starts group j's fit.
        for (std::size_t j = 0; j < count; ++j) {
          w.orientation_quats[j] = q[j] * w.q_rest_conjugate[j];
          w.orientation_terms[j] = rotation_matrix(w.orientation_quats[j]);
        }
        for (std::size_t j = 0; j < count; ++j) w.displacement[j].setZero();
        for (std::size_t c = 1; c < count; ++c) {
          const std::size_t lo = c - 1;
          const std::size_t members = c + 1 < count ? 3 : 2;
          const Real* gw = &w.group_weights[3 * c];
          const Real* ge = &w.group_ellipsoid[3 * c];
          const Vec3* rest = &w.group_rest[3 * c];
          const Vec3* weighted_rest = &w.group_weighted_rest[3 * c];
          // A = Σ w_i (x_i - c)(x̄_i - c̄)ᵀ + e Σ w_i E_i: the ellipsoid term of Müller & Chentanez
          // 2011 (e = a²/5) with each particle's orientation defines twist even on a chain.
          const Mat3* E = &w.orientation_terms[lo];
          Vec3 centroid = gw[0] * x[lo] + gw[1] * x[lo + 1];
          Mat3 A = x[lo] * weighted_rest[0].transpose() + x[lo + 1] * weighted_rest[1].transpose();
          Mat3 orientations;
          if (lo >= 2) {
            orientations = E[0] + E[1];  // dynamic particles all weigh 1
          } else {
            orientations = ge[0] * E[0] + ge[1] * E[1];
          }
          if (members == 3) {
            centroid += gw[2] * x[lo + 2];
            A += x[lo + 2] * weighted_rest[2].transpose();
            if (lo >= 2) {
              orientations += E[2];
            } else {
              orientations += ge[2] * E[2];
            }
          }
          A += lo >= 2 ? Mat3(ellipsoid * orientations) : orientations;
          // Rotational part of A: one warm-started step of Müller et al. 2016 (see extract_rotation),
          // from the guess q_c q̄_c⁻¹ whose matrix E_c is already at hand.
          const Mat3& G = w.orientation_terms[c];
          const Vec3 torque = G.col(0).cross(A.col(0)) + G.col(1).cross(A.col(1)) + G.col(2).cross(A.col(2));
          const Real denom = std::abs(G.col(0).dot(A.col(0)) + G.col(1).dot(A.col(1)) + G.col(2).dot(A.col(2))) + 1e-12;
          const Vec3 omega = torque * (Real(0.5) / denom);
          Quat R = w.orientation_quats[c];
          Mat3 Rm = G;
          if (omega.squaredNorm() >= Real(0.25e-24)) {
            R = unit(Quat(1, omega.x(), omega.y(), omega.z()) * R);
            Rm = rotation_matrix(R);
          }
          for (std::size_t i = 0; i < members; ++i) {
            const std::size_t j = lo + i;
            if (j < 2) continue;
            w.displacement[j] += Rm * rest[i] + centroid - x[j];
          }
          w.new_q[c] = R * q_rest[c];
        }
        for (std::size_t j = 2; j < count; ++j) x[j] += (stiffness * w.inverse_hits[j]) * w.displacement[j];
        for (std::size_t c = 1; c < count; ++c) {
          const Quat& target = w.new_q[c];
          // Blend towards the (sign-aligned) target; the normalisation absorbs |target| != 1.
          const Real sign = target.dot(q[c]) < 0 ? -stiffness : stiffness;
          q[c] = unit(Quat((1 - stiffness) * q[c].coeffs() + sign * target.coeffs()));
        }
        // Inextensibility: PBD distance constraints, root (kinematic) to tip.
        project_distance(x[1], x[2], 0, 1, w.lengths[0]);
        for (std::size_t k = 1; k < n; ++k) project_distance(x[k + 1], x[k + 2], 1, 1, w.lengths[k]);
        if (!colliders.empty()) {
          for (std::size_t j = 2; j < count; ++j) push_out_of_colliders(x[j], colliders, p.radius);
        }
      }
      // Inextensibility (docs/algorithms.md §3.3 step 3): the mass-weighted
      // projection onto the bone lengths (both ends of every segment move, momentum is kept;
      // rod/inextensibility.hpp), then the collider push-out.
      const bool converged =
          project_chain_lengths(x + 1, n + 1, w.lengths.data(), w.inverse_mass.data(), w.projection.data());
      bool pushed = false;
      if (!colliders.empty()) {
        for (std::size_t j = 2; j < count; ++j) pushed = push_out_of_colliders(x[j], colliders, p.radius) || pushed;
      }
      // What the projection left (a contact, a step it did not fully converge in) is closed
      // joint by joint from the root, each onto its bone length and out of the colliders, so
      // lengths hold exactly on output. Alone, as the length pass this once was, this one-sided
      // "follow the leader" correction passed every correction down to the tip as velocity and
      // pumped energy into chains of ten or more bones (§3.3); here it moves joints by
      // round-off, or only in contact, where the push-out dissipates anyway.
      for (std::size_t k = 0; k < n && (pushed || !converged); ++k) {
        Vec3& a = x[k + 1];
        Vec3& b = x[k + 2];
        for (int pass = 0; pass < 4; ++pass) {
          const Vec3 d = b - a;
          const Real len = d.norm();
          b = len > 1e-12 ? Vec3(a + d * (w.lengths[k] / len))
                          : Vec3(a + q[k + 1] * (w.lengths[k] * rod.geometry.segment_axis(k)));
          if (colliders.empty() || !push_out_of_colliders(b, colliders, p.radius)) break;
        }
      }
      for (std::size_t j = 2; j < count; ++j) s.v[j] = (x[j] - s.prev_x[j]) * inverse_dt;
      for (std::size_t j = 1; j < count; ++j) s.omega[j] = angular_velocity(s.prev_q[j], q[j], dt);
    }
    if (budgeted && ++s.window.steps >= p.substeps) {
      // The window closes with the root where this substep left it (x[1], q[0]).
      bool rests = false;
      // Each group's rotation from the last iteration starts the energy's exact fit.
      w.new_q[0] = q[0];
      for (std::size_t c = 1; c < count; ++c) w.new_q[c] = w.new_q[c] * w.q_rest_conjugate[c];
      const Real shape = close_energy_window(count, s, w.x_rest.data(), w.q_rest.data(), w.lengths.data(), ellipsoid,
                                             kappa, gravity, x[1], q[0], Real(p.substeps - s.window.first) * base_dt,
                                             colliders, p.radius, w.new_q.data(), w.budget, rests);
      open_energy_window(count, s, x[1], q[0], shape, gravity, rests, 0);
    }
  }
  if (budgeted && s.window.steps > s.window.first && !s.window.asleep) {
    // The frame ends inside a window: what the user sees is held to the budget too. Closed here
    // and opened again at the same phase, so the next window still ends on the 1/24 s grid.
    const int phase = s.window.steps;
    bool rests = false;
    w.new_q[0] = q[0];
    for (std::size_t c = 1; c < count; ++c) w.new_q[c] = w.new_q[c] * w.q_rest_conjugate[c];
    const Real shape = close_energy_window(count, s, w.x_rest.data(), w.q_rest.data(), w.lengths.data(), ellipsoid,
                                           kappa, gravity, x[1], q[0], Real(phase - s.window.first) * base_dt,
                                           colliders, p.radius, w.new_q.data(), w.budget, rests);
    open_energy_window(count, s, x[1], q[0], shape, gravity, false, phase);
  }
  s.anchor_position = anchor_end;
  s.anchor_rotation = anchor_end_rotation;
  if (steps == 0) {
    // No substep this frame: the chain still follows its root rigidly.
    const Quat delta = anchor_end_rotation * anchor_start_rotation.conjugate();
    for (std::size_t j = 0; j < count; ++j) {
      s.x[j] = anchor_end + delta * (s.x[j] - anchor_start);
      s.q[j] = (delta * s.q[j]).normalized();
    }
  }
}

}  // namespace kodawari::rod
