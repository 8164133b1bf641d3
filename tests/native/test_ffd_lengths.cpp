#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "ffd_test_curves.hpp"
#include "kodawari/ffd/bspline.hpp"
#include "kodawari/ffd/lengths.hpp"

using namespace kodawari;
using namespace kodawari::ffd;

TEST(FfdLengths, SeedPassKeepsTheMovedPointAndEveryRestLength) {
  const Vec3List rest = fixtures::straight_axis(6, 5);
  const std::vector<Real> lengths = segment_lengths(rest);
  Vec3List moved = rest;
  moved[3] += Vec3(0.2, 0.9, -0.3);
  const Vec3List kept = preserve_lengths(moved, lengths, 3);
  EXPECT_EQ(kept[3], moved[3]);
  const std::vector<Real> after = segment_lengths(kept);
  for (std::size_t i = 0; i < lengths.size(); ++i) EXPECT_NEAR(after[i], lengths[i], 1e-12);
  // Each neighbour lies on the segment from its old place toward the placed point.
  const Vec3 toward = (moved[2] - kept[3]).normalized();
  EXPECT_LT(((kept[2] - kept[3]).normalized() - toward).norm(), 1e-12);
}

namespace {
// A swimming body's axis: lateral offsets growing toward the tail.
Vec3List swim_bend(const Vec3List& rest, Real tail_amplitude, Real phase) {
  Vec3List bent = rest;
  const int n = static_cast<int>(rest.size());
  for (int i = 0; i < n; ++i) {
    const Real s = Real(i) / (n - 1);
    bent[i].y() += tail_amplitude * s * s * std::sin(2 * kPi * s - phase);
  }
  return bent;
}
}  // namespace

TEST(FfdLengths, BentAxisKeepsArcLengthWithinHalfAPercentAfterTheHeadPass) {
  // Tail swing 0.08 of the body (a cruising fish swings ~0.05-0.065 each side).
  const Vec3List rest = fixtures::straight_axis(8, 1.0);
  const std::vector<Real> lengths = segment_lengths(rest);
  const Real rest_length = curve_length(CubicBSpline(rest));
  for (Real phase : {0.0, 0.8, 1.6, 2.4, 3.2, 4.0, 4.8, 5.6}) {
    const Vec3List bent = swim_bend(rest, 0.08, phase);
    const Real stretched = curve_length(CubicBSpline(bent));
    const Real kept = curve_length(CubicBSpline(preserve_lengths_from_head(bent, lengths)));
    EXPECT_GT(std::abs(stretched - rest_length) / rest_length, 0.005) << "the unkept bend must stretch, phase " << phase;
    EXPECT_LT(std::abs(kept - rest_length) / rest_length, 0.005) << "phase " << phase;
  }
}

TEST(FfdLengths, ArcLengthTargetHoldsEvenForStrongBends) {
  const Vec3List rest = fixtures::straight_axis(6, 1.0);
  const std::vector<Real> lengths = segment_lengths(rest);
  const Real rest_length = curve_length(CubicBSpline(rest));
  for (Real phase : {0.0, 1.0, 2.0, 3.0}) {
    const Vec3List bent = swim_bend(rest, 0.25, phase);
    const Real seed_only = curve_length(CubicBSpline(preserve_lengths_from_head(bent, lengths)));
    EXPECT_GT(std::abs(seed_only - rest_length) / rest_length, 0.005) << "strong bends need the arc-length target";
    const Vec3List kept = preserve_lengths_from_head(bent, lengths, rest_length);
    EXPECT_NEAR(curve_length(CubicBSpline(kept)), rest_length, 1e-8);
    EXPECT_EQ(kept[0], bent[0]);
    // One common scale: the segments keep their rest proportions.
    const std::vector<Real> after = segment_lengths(kept);
    for (std::size_t i = 1; i < after.size(); ++i) EXPECT_NEAR(after[i] / after[0], lengths[i] / lengths[0], 1e-12);
  }
}

TEST(FfdLengths, BadInputThrows) {
  const Vec3List points = fixtures::straight_axis(4);
  EXPECT_THROW(preserve_lengths(points, {1, 1}, 0), std::invalid_argument);
  EXPECT_THROW(preserve_lengths(points, {1, 0, 1}, 0), std::invalid_argument);
  EXPECT_THROW(preserve_lengths(points, {1, 1, 1}, 4), std::invalid_argument);
  EXPECT_THROW(preserve_lengths(points, {1, 1, 1}, -1), std::invalid_argument);
  EXPECT_THROW(preserve_lengths(points, {1, 1, 1}, 0, Real(-1)), std::invalid_argument);
}
