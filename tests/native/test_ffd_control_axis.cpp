#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "ffd_test_curves.hpp"
#include "kodawari/ffd/control_axis.hpp"

using namespace kodawari;
using namespace kodawari::ffd;

namespace {

Real max_distance(const std::vector<float>& a, const std::vector<float>& b) {
  Real worst = 0;
  for (std::size_t i = 0; i < a.size(); i += 3) {
    worst = std::max(worst, (Vec3(a[i], a[i + 1], a[i + 2]) - Vec3(b[i], b[i + 1], b[i + 2])).norm());
  }
  return worst;
}

// A tube of vertices around a curved rest axis, including caps past both ends.
std::vector<float> tube_around(const Vec3List& axis, std::size_t count) {
  const FrameList frames = axis_frames(axis, {}, std::nullopt, 257);
  std::vector<float> out(3 * count);
  std::mt19937 rng(11);
  std::uniform_real_distribution<Real> unit(0, 1);
  for (std::size_t i = 0; i < count; ++i) {
    const Frame& f = frames[std::min<std::size_t>(256, static_cast<std::size_t>(unit(rng) * 257))];
    const Real a = 2 * kPi * unit(rng), r = 0.25 * unit(rng);
    const Real past = i % 10 == 0 ? (f.origin == frames.back().origin ? 0.3 : -0.3) * unit(rng) : 0;
    const Vec3 p = f.origin + r * std::cos(a) * f.e2 + r * std::sin(a) * f.e3 + past * f.e1;
    for (int k = 0; k < 3; ++k) out[3 * i + k] = static_cast<float>(p[k]);
  }
  return out;
}

}  // namespace

TEST(FfdControlAxis, DeformAtRestRebuildsAStraightBoxWithinTolerance) {
  const Vec3List axis = fixtures::straight_axis();
  const std::vector<float> mesh = fixtures::box_mesh(20000);
  const AxisBinding binding(axis, mesh.data(), 20000, {}, std::nullopt);
  std::vector<float> out(mesh.size());
  binding.deform(axis, {}, std::nullopt, out.data());
  EXPECT_LT(max_distance(out, mesh), 1e-5 * curve_length(CubicBSpline(axis)));
}

TEST(FfdControlAxis, DeformAtRestRebuildsATubeAroundAHelixWithTwist) {
  const Vec3List axis = fixtures::helix(16, 1, 0.2, 1.5);
  std::vector<Real> twist(16);
  for (int i = 0; i < 16; ++i) twist[i] = 0.3 * std::sin(i);
  const std::vector<float> mesh = tube_around(axis, 20000);
  const AxisBinding binding(axis, mesh.data(), 20000, twist, std::nullopt);
  std::vector<float> out(mesh.size());
  binding.deform(axis, twist, std::nullopt, out.data());
  EXPECT_LT(max_distance(out, mesh), 1e-5 * curve_length(CubicBSpline(axis)));
}

TEST(FfdControlAxis, VerticesPastTheEndsKeepTheirOffsetAlongTheTangent) {
  const Vec3List axis = fixtures::straight_axis(5, 4);
  const std::vector<float> mesh = {-0.5f, 0.1f, 0.0f, 2.0f, 0.2f, 0.0f, 4.5f, 0.0f, 0.1f};
  const AxisBinding binding(axis, mesh.data(), 3, {}, std::nullopt);
  EXPECT_NEAR(binding.coordinates()[0].w, -0.5, 1e-6);
  EXPECT_EQ(binding.coordinates()[1].w, 0.0f);
  EXPECT_NEAR(binding.coordinates()[2].w, 0.5, 1e-6);
  // Turn the tail leg by 90 degrees: the tail tip follows the end frame.
  Vec3List bent = axis;
  bent[4] = bent[3] + Vec3(0, 1, 0);
  std::vector<float> out(9);
  binding.deform(bent, {}, std::nullopt, out.data());
  const Vec3 tip(out[6], out[7], out[8]);
  EXPECT_NEAR((tip - bent[4]).norm(), std::hypot(0.5, 0.1), 1e-5);
  EXPECT_NEAR((tip - bent[4]).dot(Vec3(0, 1, 0)), 0.5, 1e-5);  // still 0.5 past the end, along the new tangent
}

TEST(FfdControlAxis, RigidMotionOfTheAxisMovesTheMeshRigidly) {
  const Vec3List axis = fixtures::s_curve(8);
  const std::vector<float> mesh = tube_around(axis, 5000);
  const Vec3 up(0, 0, 1);
  const AxisBinding binding(axis, mesh.data(), 5000, {}, up);
  const Mat3 rotation = Eigen::AngleAxis<Real>(2.1, Vec3(0.3, 1, -0.4).normalized()).toRotationMatrix();
  const Vec3 shift(-2, 5, 1);
  Vec3List moved;
  for (const Vec3& p : axis) moved.push_back(rotation * p + shift);
  std::vector<float> out(mesh.size()), expected(mesh.size());
  binding.deform(moved, {}, Vec3(rotation * up), out.data());
  for (std::size_t i = 0; i < mesh.size(); i += 3) {
    const Vec3 p = rotation * Vec3(mesh[i], mesh[i + 1], mesh[i + 2]) + shift;
    for (int k = 0; k < 3; ++k) expected[i + k] = static_cast<float>(p[k]);
  }
  EXPECT_LT(max_distance(out, expected), 1e-5 * curve_length(CubicBSpline(axis)));
}

TEST(FfdControlAxis, TranslationWithoutUpKeepsTheRoll) {
  const Vec3List axis = fixtures::helix(10);
  const std::vector<float> mesh = tube_around(axis, 2000);
  const AxisBinding binding(axis, mesh.data(), 2000, {}, std::nullopt);
  Vec3List moved;
  for (const Vec3& p : axis) moved.push_back(p + Vec3(1, 2, 3));
  std::vector<float> out(mesh.size());
  binding.deform(moved, {}, std::nullopt, out.data());
  for (std::size_t i = 0; i < mesh.size(); i += 3) {
    EXPECT_NEAR(out[i] - mesh[i], 1.0, 2e-5);
    EXPECT_NEAR(out[i + 1] - mesh[i + 1], 2.0, 2e-5);
    EXPECT_NEAR(out[i + 2] - mesh[i + 2], 3.0, 2e-5);
  }
}

TEST(FfdControlAxis, ResultsAreBitIdenticalForAnyThreadCountAndRun) {
  const Vec3List axis = fixtures::straight_axis(7, 4);
  const std::size_t count = 200003;
  const std::vector<float> mesh = fixtures::box_mesh(count);
  const AxisBinding one(axis, mesh.data(), count, {}, std::nullopt, 1);
  const AxisBinding many(axis, mesh.data(), count, {}, std::nullopt, 3);
  ASSERT_EQ(std::memcmp(one.coordinates().data(), many.coordinates().data(), count * sizeof(AxisCoordinate)), 0);
  Vec3List bent = fixtures::s_curve(7);
  std::vector<Real> twist = {0, 0.1, 0.2, 0.4, 0.2, 0, -0.3};
  std::vector<float> reference(3 * count);
  one.deform(bent, twist, std::nullopt, reference.data(), 1);
  for (unsigned threads : {1u, 2u, 3u, 5u, 8u}) {
    std::vector<float> out(3 * count);
    many.deform(bent, twist, std::nullopt, out.data(), threads);
    EXPECT_EQ(std::memcmp(out.data(), reference.data(), out.size() * sizeof(float)), 0) << threads << " threads";
  }
}

TEST(FfdControlAxis, ACurveBeyondFloatRangeThrowsBeforeWritingAnyVertex) {
  // `out` may be a shape key the user sees: a refused frame must leave it as it was.
  const Vec3List axis = fixtures::straight_axis();
  const std::vector<float> mesh = fixtures::box_mesh(100);
  const AxisBinding binding(axis, mesh.data(), 100, {}, std::nullopt);
  Vec3List huge;
  for (const Vec3& p : axis) huge.push_back(p * 1e39);  // finite in double, not in float
  std::vector<float> out(300, 7.0f);
  EXPECT_THROW(binding.deform(huge, {}, std::nullopt, out.data()), std::invalid_argument);
  for (float value : out) ASSERT_EQ(value, 7.0f);
}

TEST(FfdControlAxis, BadInputThrowsNamingTheArgument) {
  const Vec3List axis = fixtures::straight_axis();
  const std::vector<float> mesh = fixtures::box_mesh(10);
  auto message = [](auto&& call) {
    try {
      call();
    } catch (const std::invalid_argument& e) {
      return std::string(e.what());
    }
    return std::string("no exception");
  };
  EXPECT_NE(message([&] { AxisBinding(axis, mesh.data(), 0, {}, std::nullopt); }).find("vertices"), std::string::npos);
  std::vector<float> nan_mesh = mesh;
  nan_mesh[4] = std::nanf("");
  EXPECT_NE(message([&] { AxisBinding(axis, nan_mesh.data(), 10, {}, std::nullopt); }).find("vertices"), std::string::npos);
  EXPECT_NE(message([&] { AxisBinding(axis, mesh.data(), 10, {0.1, 0.2}, std::nullopt); }).find("twist"), std::string::npos);
  EXPECT_NE(message([&] { AxisBinding(axis, mesh.data(), 10, {}, Vec3(2, 0, 0)); }).find("up"), std::string::npos);
  const AxisBinding binding(axis, mesh.data(), 10, {}, std::nullopt);
  std::vector<float> out(30);
  EXPECT_NE(message([&] { binding.deform(fixtures::straight_axis(5), {}, std::nullopt, out.data()); }).find("control_points"),
            std::string::npos);
}

// docs/algorithms.md §1.6: what the Fish Swim modifier computes from the packed (s, u, v)
// attribute and the frame table equals deform(), caps past both ends included (their w
// rides in s outside [0, 1024]), and a released binding still gives the frame table.
TEST(FfdControlAxis, PackedCoordinatesAndTheFrameTableGiveDeformsPositions) {
  const Vec3List rest = fixtures::s_curve(16);
  const std::size_t count = 20000;
  const std::vector<float> mesh = tube_around(rest, count);
  AxisBinding binding(rest, mesh.data(), count, {}, std::nullopt);
  Vec3List bent = rest;
  for (std::size_t i = 0; i < bent.size(); ++i) bent[i] += Vec3(0, 0.3 * std::sin(0.7 * Real(i)), 0.1 * Real(i) / 16);
  std::vector<float> expected(3 * count);
  binding.deform(bent, {}, std::nullopt, expected.data());

  const float length = static_cast<float>(curve_length(CubicBSpline(rest)));
  const float end_scale = float(kTableSegments) / length;
  std::vector<float> packed(3 * count);
  binding.packed_coordinates(end_scale, packed.data());
  std::size_t beyond = 0;
  for (std::size_t i = 0; i < count; ++i) beyond += packed[3 * i] < 0 || packed[3 * i] > float(kTableSegments);
  EXPECT_GT(beyond, 10u);  // caps past the ends are among them

  binding.release_coordinates();
  EXPECT_EQ(binding.count(), count);
  EXPECT_THROW(binding.deform(bent, {}, std::nullopt, expected.data()), std::logic_error);
  FrameTable table;
  binding.frame_table(bent, {}, std::nullopt, table);
  std::vector<float> out(3 * count);
  deform_packed(table, packed.data(), count, end_scale, out.data());
  EXPECT_LT(max_distance(out, expected), 1e-5 * length);
}

namespace {
// A clamped uniform cubic B-spline is linear in t when its control points sit at the knots'
// Greville abscissae (the mean of each point's three inner knots): linear precision.
Vec3List greville_line(int n, Real length) {
  std::vector<Real> knots(n + 4);
  for (int i = 0; i < n + 4; ++i) knots[i] = std::clamp(Real(i - 3) / Real(n - 3), Real(0), Real(1));
  Vec3List points;
  for (int i = 0; i < n; ++i) points.emplace_back(length * (knots[i + 1] + knots[i + 2] + knots[i + 3]) / 3, 0, 0);
  return points;
}

std::vector<float> packed_of(const AxisBinding& binding, float end_scale) {
  std::vector<float> packed(3 * binding.count());
  binding.packed_coordinates(end_scale, packed.data());
  return packed;
}
}  // namespace

// docs/algorithms.md §1.6: which packed coordinates are affine in the rest position is
// measured on every vertex, never assumed; the rows that hold give the bound values.
TEST(FfdAffineCoordinates, AStraightAxisGivesAffineOffsetsAndItsParameterOnlyWhenLinearInT) {
  const std::size_t count = 20000;
  const std::vector<float> mesh = fixtures::box_mesh(count);  // caps past both ends too
  const Real length = 4;
  const float end_scale = float(kTableSegments / length);
  // Evenly spaced control points: the clamped ends make t run faster near the ends, so s is
  // not affine, while u and v are (the frames never turn along a straight axis).
  const AxisBinding even(fixtures::straight_axis(8, length), mesh.data(), count, {}, std::nullopt);
  const AffineCoordinates a = even.affine_coordinates(mesh.data(), count, end_scale, 1e-6);
  EXPECT_FALSE(a.holds[0]);
  EXPECT_GT(a.worst[0], 1e-3);
  EXPECT_TRUE(a.holds[1] && a.holds[2]);
  // Control points at the Greville abscissae: t is proportional to the arc, s is affine too,
  // beyond the ends included (there s = w * end_scale, the same slope).
  const AxisBinding linear(greville_line(8, length), mesh.data(), count, {}, std::nullopt);
  const AffineCoordinates b = linear.affine_coordinates(mesh.data(), count, end_scale, 1e-6);
  EXPECT_TRUE(b.holds[0] && b.holds[1] && b.holds[2]) << b.worst[0] << " " << b.worst[1] << " " << b.worst[2];

  // What fill_affine_coordinates writes from the rest positions deforms like the bound values.
  std::vector<float> packed = packed_of(linear, end_scale);
  std::vector<float> computed(packed.size(), -1.0f);
  fill_affine_coordinates(b, mesh.data(), count, computed.data());
  Vec3List bent = greville_line(8, length);
  for (std::size_t i = 0; i < bent.size(); ++i) bent[i] += Vec3(0, 0.4 * std::sin(0.9 * Real(i)), 0);
  FrameTable table;
  linear.frame_table(bent, {}, std::nullopt, table);
  std::vector<float> from_bound(packed.size()), from_rest(packed.size());
  deform_packed(table, packed.data(), count, end_scale, from_bound.data());
  deform_packed(table, computed.data(), count, end_scale, from_rest.data());
  EXPECT_LT(max_distance(from_rest, from_bound), 2e-6 * length);
}

TEST(FfdAffineCoordinates, ACurvedAxisKeepsEveryCoordinateAndARowThatHoldsIsTheOnlyOneWritten) {
  const Vec3List rest = fixtures::s_curve(16);
  const std::size_t count = 5000;
  const std::vector<float> mesh = tube_around(rest, count);
  const AxisBinding binding(rest, mesh.data(), count, {}, std::nullopt);
  const float length = static_cast<float>(curve_length(CubicBSpline(rest)));
  const AffineCoordinates a = binding.affine_coordinates(mesh.data(), count, float(kTableSegments) / length, 1e-6);
  EXPECT_FALSE(a.holds[0] || a.holds[1] || a.holds[2]);
  std::vector<float> packed(3 * count, 7.0f);
  fill_affine_coordinates(a, mesh.data(), count, packed.data());
  for (float value : packed) ASSERT_EQ(value, 7.0f);
  EXPECT_THROW(binding.affine_coordinates(mesh.data(), count - 1, 1.0f, 1e-6), std::invalid_argument);
  AxisBinding released(rest, mesh.data(), count, {}, std::nullopt);
  released.release_coordinates();
  EXPECT_THROW(released.affine_coordinates(mesh.data(), count, 1.0f, 1e-6), std::logic_error);
}
