// The ground heightfield lookup never indexes outside its grid: a NaN or infinite
// origin, an infinite cell or a NaN query point (a diverged body path) give a height
// from the grid, not a wild read (issue 11 item 1: NaN reached an integer cast).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>

#include "kodawari/gait/rig.hpp"

using namespace kodawari;
using namespace kodawari::gait;

namespace {
constexpr Real kNaN = std::numeric_limits<Real>::quiet_NaN();
constexpr Real kInf = std::numeric_limits<Real>::infinity();

Heightfield ramp() {  // 3 x 2 grid, height = column index
  Heightfield g;
  g.nx = 3;
  g.ny = 2;
  g.heights = {0, 1, 2, 0, 1, 2};
  return g;
}
}  // namespace

TEST(GaitHeightfield, NonFiniteOriginCellOrPointStaysOnTheGrid) {
  const Heightfield valid = ramp();  // finite input: bilinear inside, clamped outside
  EXPECT_DOUBLE_EQ(valid.at(0.5, 0.5), 0.5);
  EXPECT_DOUBLE_EQ(valid.at(-10, 0), 0);
  EXPECT_DOUBLE_EQ(valid.at(10, 0), 2);
  for (Real x0 : {kNaN, kInf, -kInf}) {
    Heightfield g = ramp();
    g.x0 = x0;
    g.y0 = x0;
    const Real h = g.at(0.5, 0.5);
    EXPECT_TRUE(h >= 0 && h <= 2) << "x0 = y0 = " << x0 << " gave " << h;
  }
  Heightfield g = ramp();
  g.cell = kInf;
  EXPECT_DOUBLE_EQ(g.at(kInf, kInf), 0);  // inf / inf is NaN
  g.cell = 1;
  for (Real x : {kNaN, kInf, -kInf}) {
    const Real h = g.at(x, x);
    EXPECT_TRUE(h >= 0 && h <= 2) << "point " << x << " gave " << h;
  }
}

TEST(GaitHeightfield, TooFewHeightsReadsNothing) {
  Heightfield g = ramp();
  g.heights.resize(2);
  EXPECT_DOUBLE_EQ(g.at(1.5, 0.5), 0);
}
