#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "ffd_test_curves.hpp"
#include "kodawari/ffd/control_axis.hpp"

using namespace kodawari;
using namespace kodawari::ffd;

namespace {

Mat3 rows(const Frame& f) {
  Mat3 m;
  m.row(0) = f.e1.transpose();
  m.row(1) = f.e2.transpose();
  m.row(2) = f.e3.transpose();
  return m;
}

Real angle_between(const Vec3& a, const Vec3& b) { return std::atan2(a.cross(b).norm(), a.dot(b)); }

// Rotation angle of the frame from f to g, and the tangent's turn: a flip shows
// as a frame rotation near pi while the tangent barely turns.
void expect_no_flips(const FrameList& frames) {
  Real worst_ratio = 0;
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) {
    const Mat3 turn = rows(frames[i + 1]).transpose() * rows(frames[i]);
    const Real frame_angle = Eigen::AngleAxis<Real>(turn).angle();
    const Real tangent_angle = angle_between(frames[i].e1, frames[i + 1].e1);
    EXPECT_LE(frame_angle, tangent_angle * 1.001 + 1e-9) << "sample " << i;
    worst_ratio = std::max(worst_ratio, frame_angle / std::max(tangent_angle, 1e-12));
  }
  ::testing::Test::RecordProperty("worst_frame_to_tangent_turn_ratio", std::to_string(worst_ratio));
}

void expect_orthonormal_right_handed(const FrameList& frames) {
  for (const Frame& f : frames) {
    const Mat3 m = rows(f);
    EXPECT_LT((m * m.transpose() - Mat3::Identity()).norm(), 1e-12);
    EXPECT_NEAR(m.determinant(), 1.0, 1e-12);
  }
}

}  // namespace

TEST(FfdFrames, HelixFramesNeverTurnMoreThanTheCurve) {
  const FrameList frames = axis_frames(fixtures::helix(), {}, std::nullopt, 512);
  expect_orthonormal_right_handed(frames);
  expect_no_flips(frames);
}

TEST(FfdFrames, SCurveFramesNeverTurnMoreThanTheCurve) {
  const FrameList frames = axis_frames(fixtures::s_curve(), {}, std::nullopt, 512);
  expect_orthonormal_right_handed(frames);
  expect_no_flips(frames);
  // Across the inflections e2 stays on the same side: a Frenet normal would reverse.
  for (std::size_t i = 0; i + 1 < frames.size(); ++i) EXPECT_GT(frames[i].e2.dot(frames[i + 1].e2), 0.99);
}

TEST(FfdFrames, PlanarCurveKeepsE2OnThePlaneNormal) {
  // A rotation-minimising frame of a planar curve started on the plane normal stays on it.
  Vec3List planar = fixtures::s_curve();
  for (Vec3& p : planar) p.z() = 0;
  const FrameList frames = axis_frames(planar, {}, Vec3(0, 0, 1), 256);
  for (const Frame& f : frames) EXPECT_GT(f.e2.z(), 1 - 1e-9);
}

TEST(FfdFrames, TwistRollsTheFrameByTheBlendedAngle) {
  const Vec3List points = fixtures::s_curve(8);
  std::vector<Real> twist(8, 0.0);
  twist[5] = 1.2;
  twist[6] = 0.4;
  const FrameList plain = axis_frames(points, {}, std::nullopt, 101);
  const FrameList rolled = axis_frames(points, twist, std::nullopt, 101);
  const CubicBSpline curve(points);
  for (std::size_t i = 0; i < plain.size(); ++i) {
    const Real t = i / 100.0;
    const Real expected = curve.blend(twist, t);
    const Real roll = std::atan2(plain[i].e3.dot(rolled[i].e2), plain[i].e2.dot(rolled[i].e2));
    EXPECT_NEAR(roll, expected, 1e-12) << t;
    EXPECT_LT((plain[i].e1 - rolled[i].e1).norm(), 1e-15);
  }
}

TEST(FfdFrames, RigidMotionOfTheCurveAndUpMovesTheFramesRigidly) {
  const Vec3List points = fixtures::helix(10);
  const Mat3 rotation = Eigen::AngleAxis<Real>(0.9, Vec3(1, -2, 0.5).normalized()).toRotationMatrix();
  const Vec3 shift(3, -1, 2);
  Vec3List moved;
  for (const Vec3& p : points) moved.push_back(rotation * p + shift);
  const Vec3 up(0, 0.3, 1);
  const FrameList a = axis_frames(points, {}, up, 64);
  const FrameList b = axis_frames(moved, {}, Vec3(rotation * up), 64);
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_LT((rotation * a[i].origin + shift - b[i].origin).norm(), 1e-12);
    EXPECT_LT((rotation * a[i].e2 - b[i].e2).norm(), 1e-10);
    EXPECT_LT((rotation * a[i].e3 - b[i].e3).norm(), 1e-10);
  }
}

TEST(FfdFrames, DefaultStartNormalUsesTheLeastAlignedWorldAxis) {
  const Vec3 tangent = Vec3(1, 0.2, 0.5).normalized();
  const Vec3 normal = default_start_normal(tangent);
  EXPECT_NEAR(normal.dot(tangent), 0, 1e-15);
  EXPECT_GT(normal.y(), 0.9);  // y is the least aligned axis
  EXPECT_THROW(start_normal_from_up(Vec3(2, 0.4, 1), tangent), std::invalid_argument);
}
