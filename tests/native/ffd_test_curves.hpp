// Control polygons and meshes shared by the FFD tests.
#pragma once

#include <cmath>
#include <random>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::ffd::fixtures {

// n points evenly spaced on the x axis from 0 to length.
inline Vec3List straight_axis(int n = 6, Real length = 4) {
  Vec3List points;
  for (int i = 0; i < n; ++i) points.emplace_back(length * i / (n - 1), 0, 0);
  return points;
}

// Control points sampled on a helix of radius r, pitch per radian c, `turns` turns.
inline Vec3List helix(int n = 24, Real r = 1, Real c = 0.15, Real turns = 2.5) {
  Vec3List points;
  for (int i = 0; i < n; ++i) {
    const Real a = 2 * kPi * turns * i / (n - 1);
    points.emplace_back(r * std::cos(a), r * std::sin(a), c * a);
  }
  return points;
}

// An S-curve: one and a half sine periods in the xy plane with a slight rise in
// z, so the curvature changes sign (where a Frenet frame would flip).
inline Vec3List s_curve(int n = 16) {
  Vec3List points;
  for (int i = 0; i < n; ++i) {
    const Real x = 6.0 * i / (n - 1);
    points.emplace_back(x, 0.8 * std::sin(x * kPi / 2), 0.05 * x);
  }
  return points;
}

// A box of `count` random points around the x axis from x0 to x1, packed xyz.
inline std::vector<float> box_mesh(std::size_t count, Real x0 = -0.4, Real x1 = 4.4, unsigned seed = 7) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<Real> along(x0, x1), across(-0.35, 0.35);
  std::vector<float> vertices(3 * count);
  for (std::size_t i = 0; i < count; ++i) {
    vertices[3 * i] = static_cast<float>(along(rng));
    vertices[3 * i + 1] = static_cast<float>(across(rng));
    vertices[3 * i + 2] = static_cast<float>(0.6 * across(rng));
  }
  return vertices;
}

}  // namespace kodawari::ffd::fixtures
