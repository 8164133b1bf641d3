#include "kodawari/rod/oriented_particles.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::rod {

Quat extract_rotation(const Mat3& A, const Quat& guess, int max_iterations) {
  Quat q = guess.normalized();
  for (int it = 0; it < max_iterations; ++it) {
    const Mat3 R = q.toRotationMatrix();
    const Vec3 torque = R.col(0).cross(A.col(0)) + R.col(1).cross(A.col(1)) + R.col(2).cross(A.col(2));
    const Real denom = std::abs(R.col(0).dot(A.col(0)) + R.col(1).dot(A.col(1)) + R.col(2).dot(A.col(2))) + 1e-12;
    const Vec3 omega = torque / denom;
    const Real angle = omega.norm();
    if (angle < 1e-12) break;
    // Rotate by omega: the first-order quaternion [1, omega/2] (normalised) avoids sin/cos
    // and turns by 2 atan(|omega|/2), the same direction: the iteration still converges.
    q = (Quat(1, omega.x() / 2, omega.y() / 2, omega.z() / 2) * q).normalized();
    // Converged: the last correction was below 1e-7 rad (warm starts need 1-3 iterations).
    if (angle < 1e-7) break;
  }
  return q;
}

bool polar_rotation(const Mat3& A, Mat3& R) {
  Mat3 X = A;
  for (int it = 0; it < 24; ++it) {
    // X⁻ᵀ = cof(X) / det X.
    Mat3 cofactor;
    cofactor.col(0) = X.col(1).cross(X.col(2));
    cofactor.col(1) = X.col(2).cross(X.col(0));
    cofactor.col(2) = X.col(0).cross(X.col(1));
    const Real det = X.col(0).dot(cofactor.col(0));
    if (!(det > 1e-300) || !std::isfinite(det)) return false;
    const Mat3 inverse_transpose = cofactor / det;
    const Real gamma = std::sqrt(std::sqrt(inverse_transpose.squaredNorm() / X.squaredNorm()));
    const Mat3 next = Real(0.5) * (gamma * X + inverse_transpose / gamma);
    const Real change = (next - X).squaredNorm();
    X = next;
    // Quadratic convergence: a step of 1e-4 (|X|² = 3 at a rotation) leaves an error of about
    // 1e-8 in the new X (measured on chain groups: steps 2, 0.5, 9e-3, 1e-5, 1e-11), second
    // order, 1e-16, in the fit's energy.
    if (change < Real(1e-8)) {
      R = X;
      return true;
    }
  }
  return false;
}

bool refine_rotation(const Mat3& A, const Quat& guess, Mat3& R, int steps) {
  Quat q = guess;
  for (int step = 0; step < steps; ++step) {
    const Mat3 Rq = q.toRotationMatrix();
    const Mat3 M = Rq.transpose() * A;
    const Vec3 g(M(2, 1) - M(1, 2), M(0, 2) - M(2, 0), M(1, 0) - M(0, 1));
    const Mat3 H = Mat3::Identity() * M.trace() - Real(0.5) * (M + M.transpose());
    // H is positive definite near the maximum (σᵢ + σⱼ > 0); otherwise the guess is too far.
    const Real det = H.determinant();
    if (!(det > 0) || !(H(0, 0) > 0)) return false;
    const Vec3 omega = H.inverse() * g;
    const Real angle2 = omega.squaredNorm();
    if (!(angle2 < Real(0.25))) return false;  // more than half a radian: not close
    // The first-order quaternion turns by 2 atan(|ω|/2): third-order off, which the next step
    // takes up (quadratic convergence is kept).
    const Vec3 half = omega / 2;
    q = (q * Quat(1, half.x(), half.y(), half.z())).normalized();
    // A step under 1e-5 rad leaves an error of about 1e-10 rad after it (quadratic), 1e-20 in
    // the fit's energy.
    if (angle2 < Real(1e-10)) {
      R = q.toRotationMatrix();
      return true;
    }
  }
  return false;
}

bool push_out_of_colliders(Vec3& p, const std::vector<Collider>& colliders, Real margin) {
  bool moved = false;
  for (const Collider& c : colliders) {
    const Vec3 axis = c.end - c.start;
    const Real len2 = axis.squaredNorm();
    const Real t = len2 > 0 ? std::clamp((p - c.start).dot(axis) / len2, Real(0), Real(1)) : Real(0);
    const Vec3 closest = c.start + t * axis;
    const Vec3 d = p - closest;
    const Real dist = d.norm();
    const Real r = c.radius + margin;
    if (dist >= r) continue;
    // A point exactly on the axis has no outward direction: push along +Z, deterministically.
    const Vec3 n = dist > 1e-12 ? Vec3(d / dist) : Vec3::UnitZ();
    p = closest + r * n;
    moved = true;
  }
  return moved;
}

Quat align_axis(const Quat& q, const Vec3& axis_local, const Vec3& target_direction) {
  const Vec3 current = q * axis_local;
  // The half-way quaternion (1 + a·b, a × b) is the minimal rotation from a to b up to
  // its norm; one normalisation of the product does for both (a third of the square roots
  // of Quat::FromTwoVectors). Near a half turn the axis is ill-defined: Eigen picks one.
  const Real cosine = current.dot(target_direction);
  if (cosine < Real(-1) + Real(1e-6)) return (Quat::FromTwoVectors(current, target_direction) * q).normalized();
  const Vec3 axis = current.cross(target_direction);
  return (Quat(1 + cosine, axis.x(), axis.y(), axis.z()) * q).normalized();
}

}  // namespace kodawari::rod
