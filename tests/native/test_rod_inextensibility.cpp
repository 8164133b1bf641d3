// The chain length projection (rod/inextensibility.hpp): exact lengths, momentum kept.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "kodawari/rod/inextensibility.hpp"

using namespace kodawari;
using namespace kodawari::rod;

namespace {

// A bent chain of `count` joints, 1 cm apart, each joint but the root then moved by up to
// `jitter` along each axis.
Vec3List jittered_chain(std::size_t count, Real jitter, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> u(-jitter, jitter);
  Vec3List x(count);
  x[0] = Vec3::Zero();
  for (std::size_t j = 1; j < count; ++j) {  // bones of 1 cm, each turned 3 degrees further
    const Real a = 0.05 * Real(j);
    x[j] = x[j - 1] + 0.01 * Vec3(std::cos(a), std::sin(a), 0);
  }
  for (std::size_t j = 1; j < count; ++j) x[j] += Vec3(u(rng), u(rng), u(rng));
  return x;
}

Real worst_length_error(const Vec3List& x, const std::vector<Real>& lengths) {
  Real worst = 0;
  for (std::size_t k = 0; k + 1 < x.size(); ++k) {
    worst = std::max(worst, std::abs((x[k + 1] - x[k]).norm() - lengths[k]) / lengths[k]);
  }
  return worst;
}

}  // namespace

TEST(RodInextensibility, ChainsNearTheirLengthsReachThemWithTheRootHeld) {
  for (std::size_t count : {3u, 17u, 65u}) {
    for (unsigned seed = 0; seed < 5; ++seed) {
      Vec3List x = jittered_chain(count, 0.0001, seed);  // lengths off by up to 2 %, as after a substep
      const std::vector<Real> lengths(count - 1, 0.01);
      std::vector<Real> inverse_mass(count, 1);
      inverse_mass[0] = 0;
      const Vec3 root = x[0];
      std::vector<Real> scratch(9 * count);
      EXPECT_TRUE(project_chain_lengths(x.data(), count, lengths.data(), inverse_mass.data(), scratch.data()));
      EXPECT_LT(worst_length_error(x, lengths), 1e-5) << count << " joints, seed " << seed;
      EXPECT_EQ(x[0], root) << "the kinematic root must not move";
    }
  }
}

TEST(RodInextensibility, FarFromTheirLengthsChainsNeverGetWorse) {
  // Joints moved by up to 40 % of a bone: the linearisation may mislead on long chains; a step
  // that would make lengths worse is undone (the solver then closes the rest joint by joint).
  for (std::size_t count : {3u, 17u, 65u}) {
    for (unsigned seed = 0; seed < 5; ++seed) {
      Vec3List x = jittered_chain(count, 0.002, seed);
      const std::vector<Real> lengths(count - 1, 0.01);
      std::vector<Real> inverse_mass(count, 1);
      inverse_mass[0] = 0;
      const Real before = worst_length_error(x, lengths);
      std::vector<Real> scratch(9 * count);
      project_chain_lengths(x.data(), count, lengths.data(), inverse_mass.data(), scratch.data());
      EXPECT_LT(worst_length_error(x, lengths), before) << count << " joints, seed " << seed;
    }
  }
}

TEST(RodInextensibility, FreeChainsKeepTheirMomentum) {
  // Both ends of every segment move, weighted by inverse mass: the centre of mass stays
  // (follow-the-leader moves only the far end and drags the centre of mass with it).
  const std::size_t count = 33;
  Vec3List x = jittered_chain(count, 0.0001, 11);
  const std::vector<Real> lengths(count - 1, 0.01);
  const std::vector<Real> inverse_mass(count, 1);
  Vec3 before = Vec3::Zero();
  for (const Vec3& p : x) before += p;
  std::vector<Real> scratch(9 * count);
  project_chain_lengths(x.data(), count, lengths.data(), inverse_mass.data(), scratch.data());
  Vec3 after = Vec3::Zero();
  for (const Vec3& p : x) after += p;
  EXPECT_LT((after - before).norm() / Real(count), 1e-12);
  EXPECT_LT(worst_length_error(x, lengths), 1e-5);
}
