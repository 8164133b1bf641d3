// Pose forward kinematics (docs/algorithms.md §3.7): the composition an armature evaluates,
// on cases whose answer is known without it. (Blender's own evaluation is the reference in
// tests/blender/test_hair_prediction.py.)
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>
#include <vector>

#include "kodawari/pose/forward_kinematics.hpp"

namespace kodawari::pose {
namespace {

using Mat4 = Eigen::Matrix<double, 4, 4>;

BoneChannels bone(int parent, const Mat4& rest) {
  BoneChannels b;
  b.parent = parent;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) b.rest[r * 4 + c] = rest(r, c);
  const double identity[10] = {0, 0, 0, 1, 0, 0, 0, 1, 1, 1};
  std::copy(identity, identity + 10, b.channels);
  return b;
}

Mat4 translation(double x, double y, double z) {
  Mat4 m = Mat4::Identity();
  m.topRightCorner<3, 1>() = Vec3(x, y, z);
  return m;
}

Mat4 result(const std::vector<double>& out, int i) {
  Mat4 m;
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) m(r, c) = out[i * 16 + r * 4 + c];
  return m;
}

TEST(PoseForwardKinematics, ARestPoseGivesTheRestMatrices) {
  std::vector<BoneChannels> bones = {bone(-1, translation(0, 0, 1)), bone(0, translation(0, 0.5, 1))};
  std::vector<double> out(32);
  forward_kinematics(bones, out.data());
  EXPECT_TRUE(result(out, 0).isApprox(translation(0, 0, 1)));
  EXPECT_TRUE(result(out, 1).isApprox(translation(0, 0.5, 1)));
}

TEST(PoseForwardKinematics, AChildTurnsWithItsParentAndAHingeDoesNot) {
  // Parent turned 90 degrees about z (a quaternion given unnormalised): the child's head swings
  // round the parent's origin; a hinge child moves the same but keeps the rest orientation.
  std::vector<BoneChannels> bones = {bone(-1, Mat4::Identity()), bone(0, translation(1, 0, 0)),
                                     bone(0, translation(1, 0, 0))};
  const double half = std::sqrt(0.5);
  const double quat[4] = {2 * half, 0, 0, 2 * half};
  std::copy(quat, quat + 4, bones[0].channels + 3);
  bones[2].inherit_rotation = false;
  std::vector<double> out(48);
  forward_kinematics(bones, out.data());
  const Mat3 turn = Eigen::AngleAxis<double>(kPi / 2, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_TRUE((result(out, 1).topLeftCorner<3, 3>().isApprox(turn)));
  EXPECT_TRUE((result(out, 1).topRightCorner<3, 1>().isApprox(Vec3(0, 1, 0))));
  EXPECT_TRUE((result(out, 2).topLeftCorner<3, 3>().isApprox(Mat3::Identity())));
  EXPECT_TRUE((result(out, 2).topRightCorner<3, 1>().isApprox(Vec3(0, 1, 0))));
}

TEST(PoseForwardKinematics, EulerOrderRotatesAboutTheFirstAxisFirst) {
  std::vector<BoneChannels> bones = {bone(-1, Mat4::Identity())};
  bones[0].rotation_mode = 5;  // ZXY: z first, then x, then y
  const double angles[3] = {0.3, -0.7, 1.1};
  std::copy(angles, angles + 3, bones[0].channels + 3);
  std::vector<double> out(16);
  forward_kinematics(bones, out.data());
  const Mat3 want = Eigen::AngleAxis<double>(-0.7, Vec3::UnitY()).toRotationMatrix() *
                    Eigen::AngleAxis<double>(0.3, Vec3::UnitX()).toRotationMatrix() *
                    Eigen::AngleAxis<double>(1.1, Vec3::UnitZ()).toRotationMatrix();
  EXPECT_TRUE((result(out, 0).topLeftCorner<3, 3>().isApprox(want)));
}

TEST(PoseForwardKinematics, RefusesWhatItDoesNotModel) {
  std::vector<double> out(32);
  std::vector<BoneChannels> later_parent = {bone(1, Mat4::Identity()), bone(-1, Mat4::Identity())};
  EXPECT_THROW(forward_kinematics(later_parent, out.data()), std::invalid_argument);
  std::vector<BoneChannels> none_scale = {bone(-1, Mat4::Identity()), bone(0, Mat4::Identity())};
  none_scale[1].inherit_scale = InheritScale::kNone;
  EXPECT_THROW(forward_kinematics(none_scale, out.data()), std::invalid_argument);
  none_scale[1].inherit_rotation = false;  // under a hinge it is modelled
  EXPECT_NO_THROW(forward_kinematics(none_scale, out.data()));
}

}  // namespace
}  // namespace kodawari::pose
