// The body pose per frame: head and heading from the track, height from bob and drop,
// pitch from the fore / hind difference; written as the body bone's channels.
#include <cmath>

#include "bake_stages.hpp"

namespace kodawari::gait::stages {

BodyPoses pose_body(const BakeInput& in, const LegGeometry& legs, const BodyTrack& track, const BodyHeight& height,
                    BakeOutput& out) {
  const Rig& rig = in.rig;
  const int frames = static_cast<int>(in.target_speed.size());
  const Vec3 F = rig.forward;
  const Vec3 A = up().cross(F);  // lateral hinge axis
  const Vec2d F2 = horizontal(F);
  Real fore_d = 0, hind_d = 0;  // fore-aft distance of the fore / hind roots from the body head
  for (int leg = 0; leg < kLegCount; ++leg) (is_fore(leg) ? fore_d : hind_d) += legs.root_rel[leg].dot(F) / 2;
  BodyPoses poses;
  poses.rotations.resize(frames);
  poses.heads.resize(frames);
  for (int f = 0; f < frames; ++f) {
    const long k = static_cast<long>(f) * track.substeps;
    const Frame2& b = track.body[k];
    // Ground under the fore and hind roots, lowered by bob and reach (body_height.cpp).
    Real ground_fore = 0, ground_hind = 0;
    for (int leg = 0; leg < kLegCount; ++leg) {
      (is_fore(leg) ? ground_fore : ground_hind) += (ground_at(in, legs, track.root_at(leg, k)) - legs.ground_plane) / 2;
    }
    const Real down_fore = height.bob[f] + height.drop_fore[f] - ground_fore;
    const Real down_hind = height.bob[f] + height.drop_hind[f] - ground_hind;
    const Real span = fore_d - hind_d;
    const Real sin_pitch = span > 1e-6 ? std::clamp((down_fore - down_hind) / span, Real(-0.9), Real(0.9)) : 0;
    const Real pitch = std::asin(sin_pitch);
    const Real lift_head = -down_fore + fore_d * sin_pitch;
    const Real yaw = std::atan2(F2.x() * b.heading.y() - F2.y() * b.heading.x(), F2.dot(b.heading));
    const Mat3 R = (Eigen::AngleAxis<Real>(yaw, up()) * Eigen::AngleAxis<Real>(pitch, A)).toRotationMatrix();
    const Vec3 head(b.head.x(), b.head.y(), rig.body_head.z() + lift_head);
    // Body bone channels: basis = rest^-1 * D * rest, with D(x) = head + R (x - head_rest).
    const Mat3 basis_rot = rig.body_rest.transpose() * R * rig.body_rest;
    const Vec3 basis_loc = rig.body_rest.transpose() * (head - rig.body_head);
    Quat q(basis_rot);
    if (f > 0) {  // keep the quaternion on one side so F-curves interpolate the short way
      const Real* prev = out.body_rotation.data() + (f - 1) * 4;
      if (q.w() * prev[0] + q.x() * prev[1] + q.y() * prev[2] + q.z() * prev[3] < 0) q.coeffs() = -q.coeffs();
    }
    for (int c = 0; c < 3; ++c) out.body_location[f * 3 + c] = basis_loc[c];
    out.body_rotation[f * 4 + 0] = q.w();
    out.body_rotation[f * 4 + 1] = q.x();
    out.body_rotation[f * 4 + 2] = q.y();
    out.body_rotation[f * 4 + 3] = q.z();
    out.gait[f] = track.gait[k];
    out.speed[f] = track.speed[k];
    const Vec3 heading3(b.heading.x(), b.heading.y(), 0);
    for (int c = 0; c < 3; ++c) out.headings[f * 3 + c] = heading3[c];
    poses.rotations[f] = R;
    poses.heads[f] = head;
  }
  return poses;
}

}  // namespace kodawari::gait::stages
