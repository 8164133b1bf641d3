// The swing path: leaves and lands at rest, never goes back, lifts to its peak.
#include <gtest/gtest.h>

#include "kodawari/gait/swing_path.hpp"

using namespace kodawari;
using namespace kodawari::gait;

TEST(GaitSwingPath, ProgressStartsAndEndsAtRestAndNeverGoesBack) {
  for (Real ease : {0.01, 0.05, 0.1}) {
    EXPECT_DOUBLE_EQ(swing_progress(0, ease), 0);
    EXPECT_NEAR(swing_progress(1, ease), 1, 1e-12);
    const Real h = 1e-6;
    EXPECT_LT(swing_progress(h, ease) / h, 1e-3);             // zero speed at lift-off
    EXPECT_LT((1 - swing_progress(1 - h, ease)) / h, 1e-3);   // and at touchdown
    Real previous = 0, previous_speed = 0, largest_speed_step = 0;
    const int n = 10000;
    for (int i = 1; i <= n; ++i) {
      const Real x = swing_progress(Real(i) / n, ease);
      EXPECT_GE(x, previous);
      const Real speed = (x - previous) * n;
      largest_speed_step = std::max(largest_speed_step, std::abs(speed - previous_speed));
      previous = x;
      previous_speed = speed;
    }
    EXPECT_LT(largest_speed_step, 0.05);  // speed changes smoothly (a step would be ~1)
  }
}

TEST(GaitSwingPath, LiftPeaksWhereTheTableSays) {
  for (Real peak : {0.35, 0.4, 0.45}) {
    EXPECT_DOUBLE_EQ(swing_lift(0, peak), 0);
    EXPECT_NEAR(swing_lift(1, peak), 0, 1e-12);
    EXPECT_NEAR(swing_lift(peak, peak), 1, 1e-9);
    EXPECT_LT(swing_lift(peak - 0.05, peak), 1);
    EXPECT_LT(swing_lift(peak + 0.05, peak), 1);
  }
}

TEST(GaitSwingPath, AStrikingFootComesDownWithSpeedASoftOneDoesNot) {
  const Real h = 1e-6;
  for (Real peak : {0.35, 0.4, 0.45}) {
    for (bool strike : {false, true}) {
      EXPECT_DOUBLE_EQ(swing_lift(0, peak, strike), 0);
      EXPECT_NEAR(swing_lift(1, peak, strike), 0, 1e-12);
      EXPECT_NEAR(swing_lift(peak, peak, strike), 1, 1e-9);
      EXPECT_LT(swing_lift(peak - 0.05, peak, strike), 1);
      EXPECT_LT(swing_lift(peak + 0.05, peak, strike), 1);
    }
    // Vertical speed at touch-down, in swing heights per swing time.
    EXPECT_LT(swing_lift(1 - h, peak, false) / h, 1e-3);
    EXPECT_GT(swing_lift(1 - h, peak, true) / h, 1.0);
  }
}

TEST(GaitSwingPath, EaseShortensWithSpeedSoTheLagStaysSmall) {
  EXPECT_DOUBLE_EQ(swing_ease(0.5, 0.3), kEaseMax);
  EXPECT_LT(swing_ease(17, 0.33), swing_ease(5, 0.3));
  EXPECT_LT(ease_lag(17, 0.33), 0.08);  // at a 17 m/s gallop the hoof lags its root < 8 cm
}
