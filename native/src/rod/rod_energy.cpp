// A rod's mechanical energy (docs/algorithms.md §3.3, "The energy the solver keeps"): the
// quantity that must never grow without input motion, per unit particle mass.
#include "kodawari/rod/rod_system.hpp"

#include <stdexcept>

#include "rod_detail.hpp"

namespace kodawari::rod {

using namespace detail;

RodEnergy RodSystem::energy(std::size_t r, const Vec3& gravity) const {
  const RodDefinition& rod = rods_.at(r);
  const RodState& s = states_.at(r);
  RodEnergy out;
  if (!s.initialised) return out;
  const std::size_t n = rod.bones.size();
  const std::size_t count = n + 2;
  Vec3List x_rest;
  QuatList q_rest;
  rest_particles(rod.geometry, s.rest_local, x_rest, q_rest);
  Real mean = 0;
  for (std::size_t k = 0; k < n; ++k) mean += rod.geometry.segment_length(k);
  mean /= Real(n);
  const Real e = mean * mean / 5;  // the ellipsoid term's a²/5, as in the solver
  const Vec3 g = gravity * rod.params.gravity;

  // Kinetic: unit mass per dynamic joint; each particle's orientation has the inertia 2e of a
  // sphere of radius one segment (½ (2e) ω², the partner of the ellipsoid term below).
  for (std::size_t j = 2; j < count; ++j) {
    out.kinetic += Real(0.5) * s.v[j].squaredNorm();
    out.gravitational -= g.dot(s.x[j]);
  }
  for (std::size_t j = 1; j < count; ++j) out.kinetic += e * s.omega[j].squaredNorm();

  // Shape matching: each group's distance from its best rigid fit, the quantity whose
  // minimiser R the solver extracts (Müller & Chentanez 2011, Müller et al. 2005):
  //   U_c = min_R ½ Σ w_i |R r̄_i + c - x_i|² + ½ e Σ w_i |R - E_i|²_F,  E_i = R(q_i q̄_i⁻¹).
  // Its gradient on an interior particle is the sum over the particle's three groups of
  // (x_i - g_ci); the solver moves it by the average of those, a fraction s of the way per
  // substep, which is one implicit Euler step of a spring κ per unit mass when
  // s = κΔt²/(1 + κΔt²) (rod_detail.hpp): hence U = (κ / 3) Σ_c U_c.
  const Real kappa = shape_stiffness(rod.params);
  Real groups = 0;
  for (std::size_t c = 1; c < count; ++c) {
    const std::size_t lo = c - 1;
    const std::size_t hi = std::min(c + 1, count - 1);
    Real mass = 0;
    Vec3 centroid = Vec3::Zero(), rest_centroid = Vec3::Zero();
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      mass += wi;
      centroid += wi * s.x[i];
      rest_centroid += wi * x_rest[i];
    }
    centroid /= mass;
    rest_centroid /= mass;
    Mat3 A = Mat3::Zero();
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      A += wi * (s.x[i] - centroid) * (x_rest[i] - rest_centroid).transpose();
      A += wi * e * Mat3((s.q[i] * q_rest[i].conjugate()).toRotationMatrix());
    }
    const Mat3 R = extract_rotation(A, s.q[c] * q_rest[c].conjugate(), 64).toRotationMatrix();
    Real u = 0;
    for (std::size_t i = lo; i <= hi; ++i) {
      const Real wi = i <= 1 ? kKinematicWeight : Real(1);
      u += wi * (R * (x_rest[i] - rest_centroid) + centroid - s.x[i]).squaredNorm();
      u += wi * e * (R - Mat3((s.q[i] * q_rest[i].conjugate()).toRotationMatrix())).squaredNorm();
    }
    groups += u / 2;
  }
  out.shape_matching = kappa / 3 * groups;
  return out;
}

}  // namespace kodawari::rod
