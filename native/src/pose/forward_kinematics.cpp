// Pose matrices as an armature evaluates them before constraints (docs/algorithms.md §3.7):
//   pose(b) = P(b) · C(b),  C = T(location) · R(rotation) · S(scale)
// where P(b) is the parent transform: the rest matrix for a root bone, and for a child
// parent_pose · offset, offset = parent_rest⁻¹ · rest (the bone's rest frame in its parent's),
// with the rotation/scale part changed by the bone's inherit flags:
//   no inherited rotation (a hinge): the parent's REST orientation, scaled per axis by the
//   parent's pose scale (FULL), by the cube root of its volume (AVERAGE) or not (NONE,
//   NONE_LEGACY);
//   NONE_LEGACY under an inherited rotation: each axis of the parent's orientation normalised.
// NONE and AVERAGE under an inherited rotation (Blender removes the parent's shear there) are
// refused: not matched against Blender's evaluation under a sheared parent.
// The location always moves along parent_pose · offset (these flags leave it alone).
#include "kodawari/pose/forward_kinematics.hpp"

#include <cmath>
#include <string>

namespace kodawari::pose {

namespace {

using Mat4 = Eigen::Matrix<double, 4, 4>;

Mat4 row_major(const double* m) {
  Mat4 out;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out(r, c) = m[r * 4 + c];
  return out;
}

Mat3 euler_matrix(const double* angles, int mode) {
  // Euler order "ABC" rotates about A first: R = R_C · R_B · R_A.
  static const int orders[6][3] = {{0, 1, 2}, {0, 2, 1}, {1, 0, 2}, {1, 2, 0}, {2, 0, 1}, {2, 1, 0}};
  const int* order = orders[mode - kEulerFirst];
  Mat3 r = Mat3::Identity();
  for (int k = 0; k < 3; ++k) {
    const int axis = order[k];
    r = Eigen::AngleAxis<double>(angles[axis], Vec3::Unit(axis)).toRotationMatrix() * r;
  }
  return r;
}

Mat3 rotation_matrix(const double* rotation, int mode) {
  if (mode == kQuaternion) {
    const double n = std::sqrt(rotation[0] * rotation[0] + rotation[1] * rotation[1] + rotation[2] * rotation[2] +
                               rotation[3] * rotation[3]);
    if (n == 0.0) return Mat3::Identity();
    return Quat(rotation[0] / n, rotation[1] / n, rotation[2] / n, rotation[3] / n).toRotationMatrix();
  }
  if (mode == kAxisAngle) {
    const Vec3 axis(rotation[1], rotation[2], rotation[3]);
    if (axis.norm() == 0.0) return Mat3::Identity();
    return Eigen::AngleAxis<double>(rotation[0], axis.normalized()).toRotationMatrix();
  }
  return euler_matrix(rotation, mode);
}

Vec3 column_lengths(const Mat3& m) { return Vec3(m.col(0).norm(), m.col(1).norm(), m.col(2).norm()); }

}  // namespace

void forward_kinematics(const std::vector<BoneChannels>& bones, double* out) {
  std::vector<Mat4> pose(bones.size());
  for (std::size_t i = 0; i < bones.size(); ++i) {
    const BoneChannels& b = bones[i];
    if (b.parent >= static_cast<int>(i) || b.parent < -1) {
      throw std::invalid_argument("parents[" + std::to_string(i) + "] must be -1 or an earlier bone");
    }
    if (b.rotation_mode != kQuaternion && b.rotation_mode != kAxisAngle &&
        (b.rotation_mode < kEulerFirst || b.rotation_mode > kEulerLast)) {
      throw std::invalid_argument("rotation_modes[" + std::to_string(i) + "] must be -1..6");
    }
    Mat4 channel = Mat4::Identity();
    const Vec3 scale(b.channels[7], b.channels[8], b.channels[9]);
    channel.topLeftCorner<3, 3>() = rotation_matrix(b.channels + 3, b.rotation_mode) * scale.asDiagonal();
    channel.topRightCorner<3, 1>() = Vec3(b.channels[0], b.channels[1], b.channels[2]);
    const Mat4 rest = row_major(b.rest);
    if (b.parent < 0) {
      pose[i] = rest * channel;
      continue;
    }
    const Mat4 parent_rest = row_major(bones[b.parent].rest);
    if (std::abs(parent_rest.topLeftCorner<3, 3>().determinant()) < 1e-30) {
      throw std::invalid_argument("rest[" + std::to_string(b.parent) + "] is singular");
    }
    const Mat4 offset = parent_rest.inverse() * rest;
    const Mat4& parent = pose[b.parent];
    const Mat4 location_frame = parent * offset;
    Mat3 orientation = Mat3::Identity();  // what replaces the parent's 3x3 in the rotation/scale part
    const Mat3 parent3 = parent.topLeftCorner<3, 3>();
    if (b.inherit_rotation) {
      switch (b.inherit_scale) {
        case InheritScale::kFull: orientation = parent3; break;
        case InheritScale::kNone:
        case InheritScale::kAverage:
          throw std::invalid_argument("inherit_scale[" + std::to_string(i) +
                                      "]: NONE and AVERAGE need inherit_rotation 0 (a hinge)");
        case InheritScale::kNoneLegacy: orientation = parent3 * column_lengths(parent3).cwiseInverse().asDiagonal(); break;
      }
    } else {
      orientation = parent_rest.topLeftCorner<3, 3>();
      if (b.inherit_scale == InheritScale::kFull) orientation = orientation * column_lengths(parent3).asDiagonal();
    }
    if (b.inherit_scale == InheritScale::kAverage) orientation *= std::cbrt(std::abs(parent3.determinant()));
    Mat4 result = Mat4::Identity();
    result.topLeftCorner<3, 3>() = orientation * offset.topLeftCorner<3, 3>() * channel.topLeftCorner<3, 3>();
    result.topRightCorner<3, 1>() = (location_frame * channel.col(3)).head<3>();
    pose[i] = result;
  }
  for (std::size_t i = 0; i < bones.size(); ++i)
    for (int r = 0; r < 4; ++r)
      for (int c = 0; c < 4; ++c) out[i * 16 + r * 4 + c] = pose[i](r, c);
}

}  // namespace kodawari::pose
