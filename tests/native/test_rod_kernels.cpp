// Kernels of the rod solver: weights, rotation extraction, shape blending, FK.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "kodawari/rod/oriented_particles.hpp"
#include "kodawari/rod/shape_blend.hpp"
#include "kodawari/rod/view_weights.hpp"

using namespace kodawari;
using namespace kodawari::rod;

TEST(RodWeights, MatchTheSeedFormula) {
  std::mt19937 rng(7);
  std::normal_distribution<double> normal;
  std::uniform_real_distribution<double> log_p(std::log(0.1), std::log(64.0));
  for (int m = 0; m <= 16; ++m) {
    Vec3List dirs;
    std::vector<Real> p;
    for (int i = 0; i < m; ++i) {
      dirs.emplace_back(normal(rng), normal(rng), normal(rng));
      p.push_back(std::exp(log_p(rng)));
    }
    const Vec3 view(normal(rng), normal(rng), normal(rng));
    const auto w = view_weights(dirs, p, view);
    ASSERT_EQ(w.size(), static_cast<std::size_t>(m + 1));
    std::vector<Real> expect(m + 1);
    Real s = 0;
    for (int i = 0; i < m; ++i) {
      expect[i + 1] = std::pow((dirs[i].normalized().dot(view.normalized()) + 1) / 2, p[i]);
      s += expect[i + 1];
    }
    if (s >= 1) {
      for (int i = 1; i <= m; ++i) expect[i] /= s;
      s = 1;
    }
    expect[0] = 1 - s;
    for (int i = 0; i <= m; ++i) EXPECT_NEAR(w[i], expect[i], 1e-12);
  }
  EXPECT_EQ(view_weights({}, {}, Vec3(0, 0, 1)), std::vector<Real>{1.0});
  EXPECT_THROW(view_weights({}, {}, Vec3::Zero()), std::invalid_argument);
}

TEST(RodKernels, ExtractRotationRecoversARotatedScaledMatrix) {
  const Quat truth(Eigen::AngleAxis<Real>(1.1, Vec3(1, 2, 3).normalized()));
  const Mat3 A = truth.toRotationMatrix() * Vec3(2.0, 0.5, 1.3).asDiagonal();
  const Quat q = extract_rotation(A, Quat::Identity(), 100);
  EXPECT_LT(q.angularDistance(truth), 1e-6);
}

// The energy's polar decomposition (docs/algorithms.md §3.3): a rotation times a symmetric
// positive-definite stretch, far from a rotation (singular values 40:1, as a chain group's fit
// is mostly its length), gives the rotation back to round-off.
TEST(RodKernels, PolarRotationRecoversTheRotationOfAStretchedMatrix) {
  std::mt19937 random(7);
  std::uniform_real_distribution<Real> unit(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Quat truth = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Quat frame = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Mat3 stretch = frame.toRotationMatrix() * Vec3(2.0, 0.05, 0.6).asDiagonal() *
                         frame.toRotationMatrix().transpose();
    Mat3 R;
    ASSERT_TRUE(polar_rotation(truth.toRotationMatrix() * stretch, R));
    EXPECT_LT((R - truth.toRotationMatrix()).norm(), 1e-12);
  }
  // A reflection has no rotational part to find: refused, R untouched.
  Mat3 R = Mat3::Identity();
  EXPECT_FALSE(polar_rotation(Vec3(1.0, 1.0, -1.0).asDiagonal(), R));
  EXPECT_EQ(R, Mat3::Identity());
}

// From a guess 0.2 rad off, Newton's steps on the same fit reach what polar_rotation finds.
TEST(RodKernels, RefineRotationFromAGuessAgreesWithThePolarDecomposition) {
  std::mt19937 random(11);
  std::uniform_real_distribution<Real> unit(-1, 1);
  for (int trial = 0; trial < 50; ++trial) {
    const Quat truth = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Quat frame = Quat(unit(random), unit(random), unit(random), unit(random)).normalized();
    const Mat3 A = truth.toRotationMatrix() * frame.toRotationMatrix() * Vec3(1.0, 0.25, 0.24).asDiagonal() *
                   frame.toRotationMatrix().transpose();
    const Quat off = truth * Quat(Eigen::AngleAxis<Real>(0.2, Vec3(unit(random), unit(random), 1).normalized()));
    Mat3 R, reference;
    ASSERT_TRUE(refine_rotation(A, off, R));
    ASSERT_TRUE(polar_rotation(A, reference));
    EXPECT_LT((R - reference).norm(), 1e-9);
  }
  // A guess a half turn away is refused (R untouched): the caller falls back to polar_rotation.
  const Mat3 A = Vec3(1.0, 0.3, 0.2).asDiagonal();
  Mat3 R = Mat3::Zero();
  EXPECT_FALSE(refine_rotation(A, Quat(Eigen::AngleAxis<Real>(3.0, Vec3::UnitZ())), R));
  EXPECT_EQ(R, Mat3::Zero());
}

TEST(RodKernels, BlendKeepsLengthsAndForwardKinematicsPlacesTheTip) {
  ChainGeometry g;
  g.offsets = {Vec3(0, 0.2, 0), Vec3(0, 0.1, 0), Vec3(0, 0.1, 0)};
  g.rest_rotations = {Quat::Identity(), Quat::Identity()};
  const Quat bend(Eigen::AngleAxis<Real>(kPi / 2, Vec3::UnitZ()));
  const QuatList blended = blend_shapes({{bend, bend}}, {0.0, 1.0}, 2);
  QuatList frames;
  Vec3List heads;
  chain_forward_kinematics(g, blended, frames, heads);
  // Two quarter turns about Z: the first bone points along -X, the second along -Y.
  EXPECT_LT((heads[1] - Vec3(-0.1, 0, 0)).norm(), 1e-12);
  EXPECT_LT((heads[2] - Vec3(-0.1, -0.1, 0)).norm(), 1e-12);
  // A half blend of q and -q (the same rotation) is still that rotation.
  const Quat flipped(-bend.w(), -bend.x(), -bend.y(), -bend.z());
  const QuatList half = blend_shapes({{bend, bend}, {flipped, flipped}}, {0.0, 0.5, 0.5}, 2);
  EXPECT_LT(half[0].angularDistance(bend), 1e-12);
}

TEST(RodKernels, CollidersPushPointsToTheInflatedSurface) {
  std::vector<Collider> colliders{{Vec3::Zero(), Vec3(0, 1, 0), 0.2}};
  Vec3 p(0.1, 0.5, 0);
  EXPECT_TRUE(push_out_of_colliders(p, colliders, 0.05));
  EXPECT_NEAR(p.x(), 0.25, 1e-12);
  EXPECT_NEAR(p.y(), 0.5, 1e-12);
  Vec3 outside(1, 0, 0);
  EXPECT_FALSE(push_out_of_colliders(outside, colliders, 0.05));
}
