#include "kodawari/ffd/bspline.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace kodawari::ffd {

void validate_control_points(const Vec3List& points, const char* name) {
  if (points.size() < 4) {
    throw std::invalid_argument(std::string(name) + " needs at least 4 control points, got " +
                                std::to_string(points.size()));
  }
  Real polygon = 0;
  for (const Vec3& p : points) {
    if (!p.allFinite()) throw std::invalid_argument(std::string(name) + " contains NaN or inf");
  }
  for (std::size_t i = 0; i + 1 < points.size(); ++i) polygon += (points[i + 1] - points[i]).norm();
  // Relative threshold: coincident up to rounding at the polygon's own scale.
  const Real eps = Real(1e-9) * std::max(polygon, std::numeric_limits<Real>::min());
  for (std::size_t i = 0; i + 1 < points.size(); ++i) {
    if (!(polygon > 0) || (points[i + 1] - points[i]).norm() <= eps) {
      throw std::invalid_argument(std::string(name) + " has coincident consecutive points " + std::to_string(i) +
                                  " and " + std::to_string(i + 1));
    }
  }
}

namespace {

// de Boor's algorithm on the control values c[k - degree .. k] of span k.
template <typename T, typename Knot>
T de_boor(int degree, int k, Real t, const T* c, Knot knot) {
  std::array<T, 4> d;
  for (int j = 0; j <= degree; ++j) d[j] = c[k - degree + j];
  for (int r = 1; r <= degree; ++r) {
    for (int j = degree; j >= r; --j) {
      const Real lo = knot(j + k - degree);
      const Real alpha = (t - lo) / (knot(j + 1 + k - r) - lo);
      d[j] = (1 - alpha) * d[j - 1] + alpha * d[j];
    }
  }
  return d[degree];
}

}  // namespace

CubicBSpline::CubicBSpline(const Vec3List& control_points) : points_(control_points) {
  validate_control_points(points_, "control_points");
  const int n = count();
  spans_ = n - 3;
  // Derivative control points (NURBS Book §3.3): Q_i = p (P_{i+1} - P_i) / (U_{i+p+1} - U_{i+1}).
  first_.resize(n - 1);
  for (int i = 0; i + 1 < n; ++i) first_[i] = 3 * (points_[i + 1] - points_[i]) / (knot(i + 4) - knot(i + 1));
  second_.resize(n - 2);
  for (int i = 0; i + 2 < n; ++i) second_[i] = 2 * (first_[i + 1] - first_[i]) / (knot(i + 4) - knot(i + 2));
}

Real CubicBSpline::knot(int j) const { return Real(std::clamp(j - 3, 0, spans_)) / Real(spans_); }

int CubicBSpline::span(Real t) const {
  const Real x = std::clamp(t, Real(0), Real(1)) * spans_;
  return 3 + std::min(static_cast<int>(std::floor(x)), spans_ - 1);
}

Vec3 CubicBSpline::point(Real t) const {
  t = std::clamp(t, Real(0), Real(1));
  return de_boor(3, span(t), t, points_.data(), [this](int j) { return knot(j); });
}

Vec3 CubicBSpline::first_derivative(Real t) const {
  t = std::clamp(t, Real(0), Real(1));
  // M' has degree 2 on the knots U[1 .. n + 2]; its span index is k - 1.
  return de_boor(2, span(t) - 1, t, first_.data(), [this](int j) { return knot(j + 1); });
}

Vec3 CubicBSpline::second_derivative(Real t) const {
  t = std::clamp(t, Real(0), Real(1));
  return de_boor(1, span(t) - 2, t, second_.data(), [this](int j) { return knot(j + 2); });
}

Real CubicBSpline::blend(const std::vector<Real>& values, Real t) const {
  t = std::clamp(t, Real(0), Real(1));
  return de_boor(3, span(t), t, values.data(), [this](int j) { return knot(j); });
}

CubicBasis cubic_basis(int count, Real t) {
  const int spans = count - 3;
  auto knot = [spans](int j) { return Real(std::clamp(j - 3, 0, spans)) / Real(spans); };
  t = std::clamp(t, Real(0), Real(1));
  const int k = 3 + std::min(static_cast<int>(std::floor(t * spans)), spans - 1);
  // Triangular Cox-de Boor recursion: N[d][j] = N_{k-d+j, d}(t).
  Real left[4], right[4], lower[4] = {1, 0, 0, 0}, quadratic[3] = {0, 0, 0};
  Real current[4];
  for (int d = 1; d <= 3; ++d) {
    left[d] = t - knot(k + 1 - d);
    right[d] = knot(k + d) - t;
    Real saved = 0;
    for (int r = 0; r < d; ++r) {
      const Real temp = lower[r] / (right[r + 1] + left[d - r]);
      current[r] = saved + right[r + 1] * temp;
      saved = left[d - r] * temp;
    }
    current[d] = saved;
    for (int r = 0; r <= d; ++r) lower[r] = current[r];
    if (d == 2) {
      for (int r = 0; r < 3; ++r) quadratic[r] = current[r];
    }
  }
  CubicBasis basis;
  basis.first = k - 3;
  for (int j = 0; j < 4; ++j) {
    basis.value[j] = lower[j];
    // dN_{i,3} = 3 N_{i,2} / (U_{i+3} - U_i) - 3 N_{i+1,2} / (U_{i+4} - U_{i+1}), i = k - 3 + j;
    // the active quadratics are N_{k-2..k,2} = quadratic[0..2].
    const int i = k - 3 + j;
    Real slope = 0;
    if (j >= 1) slope += 3 * quadratic[j - 1] / (knot(i + 3) - knot(i));
    if (j <= 2) slope -= 3 * quadratic[j] / (knot(i + 4) - knot(i + 1));
    basis.slope[j] = slope;
  }
  return basis;
}

namespace {

// de Boor on M' (degree 2) at a fixed t, split in two: the ratios, which depend on the
// knots alone, and their replay on control values, the same arithmetic in the same order
// as de_boor(2, ...) (so the same bits as first_derivative).
struct DerivativeRatios {
  int first = 0;  // M' control point of d[0]
  std::array<Real, 3> alpha{};
};

DerivativeRatios derivative_ratios(int count, Real t) {
  const int spans = count - 3;
  const auto knot = [spans](int j) { return Real(std::clamp(j + 1 - 3, 0, spans)) / Real(spans); };
  t = std::clamp(t, Real(0), Real(1));
  const int k = 3 + std::min(static_cast<int>(std::floor(t * spans)), spans - 1) - 1;
  DerivativeRatios out;
  out.first = k - 2;
  int a = 0;
  for (int r = 1; r <= 2; ++r) {
    for (int j = 2; j >= r; --j) {
      const Real lo = knot(j + k - 2);
      out.alpha[static_cast<std::size_t>(a++)] = (t - lo) / (knot(j + 1 + k - r) - lo);
    }
  }
  return out;
}

Vec3 replay(const DerivativeRatios& ratios, const Vec3* c) {
  std::array<Vec3, 3> d = {c[ratios.first], c[ratios.first + 1], c[ratios.first + 2]};
  d[2] = (1 - ratios.alpha[0]) * d[1] + ratios.alpha[0] * d[2];
  d[1] = (1 - ratios.alpha[1]) * d[0] + ratios.alpha[1] * d[1];
  d[2] = (1 - ratios.alpha[2]) * d[1] + ratios.alpha[2] * d[2];
  return d[2];
}

// 8-point Gauss-Legendre on 8 sub-intervals per span: exact far below 1e-9 for any
// reasonable bend (the speed |M'| is smooth within a span).
constexpr std::array<Real, 4> kGaussX = {0.1834346424956498, 0.5255324099163290, 0.7966664774136267,
                                         0.9602898564975363};
constexpr std::array<Real, 4> kGaussW = {0.3626837833783620, 0.3137066458778873, 0.2223810344533745,
                                         0.1012285362903763};

// The ratios at every node of curve_length for a curve of `count` points, in its order;
// kept for the last counts asked (the swim measures its axis's length a few times a frame).
const std::vector<DerivativeRatios>& length_nodes(int count) {
  thread_local std::array<std::pair<int, std::vector<DerivativeRatios>>, 4> memo;
  thread_local std::size_t next = 0;
  for (const auto& [n, nodes] : memo) {
    if (n == count) return nodes;
  }
  const int pieces = 8 * (count - 3);
  const Real h = Real(1) / pieces;
  std::vector<DerivativeRatios> nodes;
  nodes.reserve(static_cast<std::size_t>(pieces) * 8);
  for (int p = 0; p < pieces; ++p) {
    const Real mid = (p + Real(0.5)) * h;
    for (int q = 0; q < 4; ++q) {
      nodes.push_back(derivative_ratios(count, mid - kGaussX[q] * h / 2));
      nodes.push_back(derivative_ratios(count, mid + kGaussX[q] * h / 2));
    }
  }
  auto& slot = memo[next];
  next = (next + 1) % memo.size();
  slot = {count, std::move(nodes)};
  return slot.second;
}

}  // namespace

Real curve_length(const CubicBSpline& curve) {
  const int pieces = 8 * (curve.count() - 3);
  const Real h = Real(1) / pieces;
  const std::vector<DerivativeRatios>& nodes = length_nodes(curve.count());
  const Vec3* c = curve.derivative_points().data();
  Real length = 0;
  std::size_t node = 0;
  for (int p = 0; p < pieces; ++p) {
    Real piece = 0;
    for (int q = 0; q < 4; ++q) {
      const Real below = replay(nodes[node], c).norm();
      const Real above = replay(nodes[node + 1], c).norm();
      node += 2;
      piece += kGaussW[q] * (below + above);
    }
    length += piece * h / 2;
  }
  return length;
}

}  // namespace kodawari::ffd
