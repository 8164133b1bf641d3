// A rod's mechanical energy (docs/algorithms.md §3.3, "The energy the solver keeps"): the
// quantity that must never grow without input motion, per unit particle mass. The solver
// measures it with the same two functions to hold each frame to its energy budget.
#include "kodawari/rod/rod_system.hpp"

#include <stdexcept>

#include "rod_detail.hpp"

namespace kodawari::rod {

using namespace detail;

namespace detail {

Real ellipsoid_term(const ChainGeometry& geometry) {
  const std::size_t n = geometry.bone_count();
  Real mean = 0;
  for (std::size_t k = 0; k < n; ++k) mean += geometry.segment_length(k);
  mean /= Real(n);
  return mean * mean / 5;  // the ellipsoid term's a²/5: a sphere of radius one segment
}

Real chain_kinetic(std::size_t count, const Vec3* x, const Vec3* v, const Vec3* omega, Real e,
                   const RigidMotion& frame) {
  // Unit mass per dynamic joint; each particle's orientation has the inertia 2e of a sphere
  // of radius one segment (½ (2e) ω², the partner of the ellipsoid term below). Relative to
  // the root's rigid motion u(x) = V + Ω × (x - o), with the centrifugal term -½ |Ω × (x - o)|²
  // (the Jacobi integral: constant along a motion in a frame turning steadily at Ω; Ω = 0 and
  // V = 0 give the plain kinetic energy).
  Real kinetic = 0;
  const bool spinning = frame.spin.squaredNorm() > 0;
  for (std::size_t j = 2; j < count; ++j) {
    if (spinning) {
      const Vec3 carried = frame.spin.cross(x[j] - frame.origin);
      kinetic += Real(0.5) * ((v[j] - frame.velocity - carried).squaredNorm() - carried.squaredNorm());
    } else {
      kinetic += Real(0.5) * (v[j] - frame.velocity).squaredNorm();
    }
  }
  for (std::size_t j = 1; j < count; ++j) kinetic += e * (omega[j] - frame.spin).squaredNorm();
  return kinetic;
}

void chain_potential(std::size_t count, const Vec3* x, const Quat* q, const Vec3* x_rest, const Quat* q_rest, Real e,
                     Real kappa, const Vec3& g, Real& gravitational, Real& shape_matching, Vec3* pull,
                     Eigen::Matrix<Real, 4, 1>* turn, const Quat* guesses) {
  gravitational = 0;
  if (pull) {
    for (std::size_t j = 0; j < count; ++j) pull[j].setZero();
  }
  if (turn) {
    for (std::size_t j = 0; j < count; ++j) turn[j].setZero();
  }
  for (std::size_t j = 2; j < count; ++j) gravitational -= g.dot(x[j]);
  // Shape matching: each group's distance from its best rigid fit, the quantity whose
  // minimiser R the solver extracts (Müller & Chentanez 2011, Müller et al. 2005):
  //   U_c = min_R ½ Σ w_i |R r̄_i + c - x_i|² + ½ e Σ w_i |R - E_i|²_F,  E_i = R(q_i q̄_i⁻¹).
  // Its gradient on an interior particle is the sum over the particle's three groups of
  // (x_i - g_ci); the solver moves it by the average of those, a fraction s of the way per
  // substep, which is one implicit Euler step of a spring κ per unit mass when
  // s = κΔt²/(1 + κΔt²) (rod_detail.hpp): hence U = (κ / 3) Σ_c U_c.
  // E_i once per particle (each belongs to up to three groups).
  thread_local std::vector<Mat3, Eigen::aligned_allocator<Mat3>> E;
  E.resize(count);
  for (std::size_t i = 0; i < count; ++i) E[i] = (q[i] * q_rest[i].conjugate()).toRotationMatrix();
  Real groups = 0;
  for (std::size_t c = 1; c < count; ++c) {
    const std::size_t lo = c - 1;
    const std::size_t hi = std::min(c + 1, count - 1);
    Real mass = 0;
    Vec3 centroid = Vec3::Zero(), rest_centroid = Vec3::Zero();
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      mass += wi;
      centroid += wi * x[i];
      rest_centroid += wi * x_rest[i];
    }
    centroid /= mass;
    rest_centroid /= mass;
    Mat3 A = Mat3::Zero();
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      A += wi * (x[i] - centroid) * (x_rest[i] - rest_centroid).transpose();
      A += wi * e * E[i];
    }
    Mat3 R;
    if (!(guesses && refine_rotation(A, guesses[c], R)) && !polar_rotation(A, R)) {
      R = extract_rotation(A, q[c] * q_rest[c].conjugate(), 64).toRotationMatrix();
    }
    Real u = 0;
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      const Vec3 offset = R * (x_rest[i] - rest_centroid) + centroid - x[i];
      u += wi * offset.squaredNorm();
      u += wi * e * (R - E[i]).squaredNorm();
      // -∂U_c/∂x_i = w_i (g_ci - x_i) (R fixed at its minimiser); each orientation is pulled
      // towards R q̄_i.
      if (pull) pull[i] += wi * offset;
      if (turn) {
        const Quat target = Quat(R) * q_rest[i];
        turn[i] += (target.dot(q[i]) < 0 ? Real(-1) : Real(1)) * target.coeffs();
      }
    }
    groups += u / 2;
  }
  shape_matching = kappa / 3 * groups;
}

}  // namespace detail

RodEnergy RodSystem::energy(std::size_t r, const Vec3& gravity) const {
  const RodDefinition& rod = rods_.at(r);
  const RodState& s = states_.at(r);
  RodEnergy out;
  if (!s.initialised) return out;
  const std::size_t count = rod.bones.size() + 2;
  Vec3List x_rest;
  QuatList q_rest;
  rest_particles(rod.geometry, s.rest_local, x_rest, q_rest);
  const Real e = ellipsoid_term(rod.geometry);
  out.kinetic = chain_kinetic(count, s.x.data(), s.v.data(), s.omega.data(), e, RigidMotion{});
  chain_potential(count, s.x.data(), s.q.data(), x_rest.data(), q_rest.data(), e, shape_stiffness(rod.params),
                  gravity * rod.params.gravity, out.gravitational, out.shape_matching);
  return out;
}

}  // namespace kodawari::rod
