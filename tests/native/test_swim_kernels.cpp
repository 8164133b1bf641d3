// The swim kernels: body wave, length keeping, fin motion, phase accumulation, speed.
#include <gtest/gtest.h>

#include <cmath>
#include <thread>
#include <vector>

#include "kodawari/ffd/bspline.hpp"
#include "kodawari/swim/body_wave.hpp"
#include "kodawari/swim/fin_motion.hpp"
#include "kodawari/swim/speed.hpp"

using namespace kodawari;
using namespace kodawari::swim;

namespace {

Vec3List straight_axis(int n, Real length) {
  Vec3List points;
  for (int i = 0; i < n; ++i) points.emplace_back(length * Real(i) / Real(n - 1), 0, 0);
  return points;
}

Real polygon_length(const Vec3List& p) {
  Real total = 0;
  for (std::size_t i = 1; i < p.size(); ++i) total += (p[i] - p[i - 1]).norm();
  return total;
}

BodyWave carangiform() {
  BodyWave wave;
  wave.wavelength = 1.0;
  wave.amplitude = 0.1;
  wave.amplitude_head = 0.01;
  wave.envelope_start = 0.4;
  wave.envelope_power = 2.0;
  return wave;
}

}  // namespace

TEST(BodyWave, EnvelopeRunsFromHeadToTailAmplitude) {
  const BodyWave wave = carangiform();
  EXPECT_DOUBLE_EQ(wave_envelope(wave, 0.0), 0.01);
  EXPECT_DOUBLE_EQ(wave_envelope(wave, 0.3), 0.01);  // before envelope_start
  EXPECT_DOUBLE_EQ(wave_envelope(wave, 1.0), 0.1);
  EXPECT_LT(wave_envelope(wave, 0.7), wave_envelope(wave, 0.9));
}

TEST(BodyWave, TailTipPeakMatchesAmplitudeWithLengthKept) {
  const Vec3List rest = straight_axis(8, 2.0);
  const BodyWave wave = carangiform();
  const Real rest_curve = ffd::curve_length(ffd::CubicBSpline(rest));
  Real peak = 0;
  for (int k = 0; k < 400; ++k) {
    const Real phase = 2 * kPi * k / 400.0;
    const Vec3List axis = body_axis(rest, Vec3(0, 1, 0), 2.0, wave, phase);
    peak = std::max(peak, std::abs(axis.back().y()));
    // The curve (the body) keeps its rest arc length; the control-point distances
    // stay equal to each other (one common scale of the rest distances).
    EXPECT_NEAR(ffd::curve_length(ffd::CubicBSpline(axis)), rest_curve, 1e-6 * rest_curve);
    for (std::size_t i = 2; i < axis.size(); ++i) {
      EXPECT_NEAR((axis[i] - axis[i - 1]).norm(), (axis[1] - axis[0]).norm(), 1e-9);
    }
    EXPECT_GE(polygon_length(axis), 2.0 - 1e-9);
  }
  // The control offsets are a least-squares fit of the curve to the wave (so its
  // wavelength is right), which leaves the tail tip within 2% of the set amplitude.
  EXPECT_NEAR(peak, 0.1 * 2.0, 0.02 * 0.2);
}

TEST(BodyWave, WaveTravelsTailward) {
  BodyWave wave = carangiform();
  wave.preserve_length = false;
  wave.amplitude_head = wave.amplitude;  // uniform amplitude: crest position is clean
  // The crest at phase φ sits where φ − 2πs/λ = π/2; a larger phase moves it tailward.
  auto crest = [&](Real phase) {
    Real best = -1, where = 0;
    for (int i = 0; i <= 1000; ++i) {
      const Real s = i / 1000.0;
      const Real y = wave_offset(wave, s, phase);
      if (y > best) best = y, where = s;
    }
    return where;
  };
  EXPECT_LT(crest(kPi / 2 + 0.5), crest(kPi / 2 + 1.5));
}

TEST(BodyWave, WithoutPreserveLengthPointsMoveOnlySideways) {
  const Vec3List rest = straight_axis(6, 1.0);
  BodyWave wave = carangiform();
  wave.preserve_length = false;
  const Vec3List axis = body_axis(rest, Vec3(0, 0, 1), 1.0, wave, 0.7);
  for (std::size_t i = 0; i < rest.size(); ++i) {
    EXPECT_DOUBLE_EQ(axis[i].x(), rest[i].x());
    EXPECT_DOUBLE_EQ(axis[i].y(), 0.0);
  }
}

TEST(BodyWave, SameInputsGiveBitIdenticalOutputs) {
  const Vec3List rest = straight_axis(12, 1.3);
  const Vec3List a = body_axis(rest, Vec3(0, 1, 0), 1.3, carangiform(), 12.345);
  const Vec3List b = body_axis(rest, Vec3(0, 1, 0), 1.3, carangiform(), 12.345);
  for (std::size_t i = 0; i < a.size(); ++i) EXPECT_EQ(a[i], b[i]);
}

// A live fish asks every frame with the same rest axis and settings, and the wave's
// phase-free part is kept between calls: a call after others (other settings, another rest
// axis, more than the kept few) is bit for bit a first call on a thread of its own.
TEST(BodyWave, AxisAfterOtherCallsIsTheAxisComputedAfresh) {
  const Vec3List rest = straight_axis(8, 1.3);
  Vec3List bent = rest;
  bent[3].y() += 0.02;
  auto axis = [](const Vec3List& points, Real amplitude, Real phase) {
    BodyWave wave = carangiform();
    wave.amplitude = amplitude;
    return body_axis(points, Vec3(0, 1, 0), 1.3, wave, phase);
  };
  auto afresh = [&](const Vec3List& points, Real amplitude, Real phase) {
    Vec3List out;
    std::thread([&] { out = axis(points, amplitude, phase); }).join();
    return out;
  };
  std::vector<Vec3List> seen;
  for (int round = 0; round < 2; ++round) {
    for (int k = 0; k < 10; ++k) {  // more settings than are kept
      seen.push_back(axis(k % 2 ? bent : rest, 0.05 + 0.01 * k, 0.3 * k));
    }
  }
  for (int k = 0; k < 10; ++k) {
    const Vec3List expected = afresh(k % 2 ? bent : rest, 0.05 + 0.01 * k, 0.3 * k);
    for (int round = 0; round < 2; ++round) {
      const Vec3List& got = seen[static_cast<std::size_t>(10 * round + k)];
      for (std::size_t i = 0; i < got.size(); ++i) EXPECT_EQ(got[i], expected[i]) << k << " " << round;
    }
  }
  // Different settings, different axis: nothing is served for the wrong inputs.
  EXPECT_NE(axis(rest, 0.05, 0.9)[7], axis(rest, 0.08, 0.9)[7]);
  EXPECT_NE(axis(rest, 0.05, 0.9)[7], axis(bent, 0.05, 0.9)[7]);
}

TEST(AccumulatePhase, ConstantFrequencyGivesTwoPiFT) {
  const std::vector<Real> f(25, 2.0);
  const std::vector<Real> phase = accumulate_phase(f, 1.0 / 24.0, 0.0);
  EXPECT_NEAR(phase.back(), 2 * kPi * 2.0 * 1.0, 1e-12);
}

TEST(AccumulatePhase, FrequencyStepKeepsPhaseContinuous) {
  std::vector<Real> f(48, 1.0);
  for (std::size_t k = 24; k < f.size(); ++k) f[k] = 4.0;
  const Real dt = 1.0 / 24.0;
  const std::vector<Real> phase = accumulate_phase(f, dt, 0.0);
  // ω·t would jump by 2π·3·1 s at the step; the accumulated phase advances by one frame's worth.
  for (std::size_t k = 1; k < phase.size(); ++k) EXPECT_LE(phase[k] - phase[k - 1], 2 * kPi * 4.0 * dt + 1e-12);
}

TEST(FinAxis, FlapKeepsClusteredRootFixedAndMovesTipForeAft) {
  // Pectoral fin sticking out sideways (+y) from a body running along +x (tailward).
  Vec3List rest{{0, 0, 0}, {0, 0.02, 0}, {0, 0.04, 0}, {0, 0.5, 0}, {0, 1, 0}};
  RootFrame frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  FinWave wave;
  wave.motion = FinMotion::Flap;
  wave.amplitude = 0.5;
  const FinPose pose = fin_axis(rest, frame, wave, kPi / 2);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(pose.points[i], rest[i]);
  EXPECT_GT(std::abs(pose.points[4].x()), 0.4);   // tip swings fore/aft
  EXPECT_NEAR(pose.points[4].z(), 0.0, 1e-12);    // not up/down
  EXPECT_NEAR((pose.points[4] - rest[2]).norm(), (rest[4] - rest[2]).norm(), 1e-12);  // rigid about the hinge
}

TEST(FinAxis, FlapFeathersEdgeOnDuringRecoveryOnly) {
  Vec3List rest{{0, 0, 0}, {0, 0.02, 0}, {0, 0.04, 0}, {0, 0.5, 0}, {0, 1, 0}};
  RootFrame frame;
  FinWave wave;
  wave.feathering = kPi / 2;
  EXPECT_NEAR(fin_axis(rest, frame, wave, 0.0).twist[4], 0.0, 1e-12);       // mid power stroke
  EXPECT_NEAR(fin_axis(rest, frame, wave, kPi).twist[4], kPi / 2, 1e-12);  // mid recovery
  EXPECT_EQ(fin_axis(rest, frame, wave, kPi).twist[0], 0.0);
  wave.feather_on_power = true;  // a blade modelled edge-on rolls on the power stroke instead
  EXPECT_NEAR(fin_axis(rest, frame, wave, 0.0).twist[4], kPi / 2, 1e-12);
  EXPECT_NEAR(fin_axis(rest, frame, wave, kPi).twist[4], 0.0, 1e-12);
}

TEST(FinAxis, UpDownMovesTipVerticallyAndTwistRolls) {
  Vec3List rest{{0, 0, 0}, {0, 0.02, 0}, {0, 0.04, 0}, {0, 0.5, 0}, {0, 1, 0}};
  RootFrame frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  FinWave wave;
  wave.motion = FinMotion::UpDown;
  wave.amplitude = 0.4;
  const FinPose up = fin_axis(rest, frame, wave, kPi / 2);
  EXPECT_GT(std::abs(up.points[4].z()), 0.3);
  EXPECT_NEAR(up.points[4].x(), 0.0, 1e-12);
  wave.motion = FinMotion::Twist;
  const FinPose twist = fin_axis(rest, frame, wave, kPi / 2);
  EXPECT_EQ(twist.points[4], rest[4]);
  EXPECT_NEAR(twist.twist[4], 0.4, 1e-12);
}

TEST(FinAxis, UndulateSendsASidewaysWaveAlongTheBase) {
  Vec3List rest;
  for (int i = 0; i < 7; ++i) rest.emplace_back(i / 6.0, 0, 0.2);
  RootFrame frame{{1, 0, 0}, {0, 1, 0}, {0, 0, 1}};
  FinWave wave;
  wave.motion = FinMotion::Undulate;
  wave.amplitude = 0.1;
  wave.wavelength = 0.5;
  const FinPose pose = fin_axis(rest, frame, wave, kPi / 2);  // the crest sits on the first point
  Real max_side = 0;
  for (std::size_t i = 0; i < rest.size(); ++i) {
    EXPECT_DOUBLE_EQ(pose.points[i].x(), rest[i].x());
    max_side = std::max(max_side, std::abs(pose.points[i].y()));
  }
  EXPECT_NEAR(std::abs(pose.points[0].y()), 0.1, 1e-12);
  EXPECT_LE(max_side, 0.1 + 1e-12);
}

TEST(Speed, BainbridgeAndStrouhal) {
  EXPECT_DOUBLE_EQ(bainbridge_speed(0.2, 8.0), 0.25 * 0.2 * 20.0);
  EXPECT_DOUBLE_EQ(bainbridge_speed(0.2, 1.0), 0.0);  // below 4/3 Hz the formula would go negative
  EXPECT_DOUBLE_EQ(strouhal_speed(2.0, 0.2, 0.25), 1.6);
  EXPECT_DOUBLE_EQ(swim_speed(SpeedMode::Strouhal, 1.0, 2.0, 0.1, 0.25), 1.6);
  EXPECT_DOUBLE_EQ(swim_speed(SpeedMode::None, 1.0, 2.0, 0.1, 0.25), 0.0);
}
