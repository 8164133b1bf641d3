#include "kodawari/ffd/lengths.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kodawari/ffd/bspline.hpp"

namespace kodawari::ffd {

std::vector<Real> segment_lengths(const Vec3List& points) {
  std::vector<Real> lengths;
  for (std::size_t i = 0; i + 1 < points.size(); ++i) lengths.push_back((points[i + 1] - points[i]).norm());
  return lengths;
}

namespace {

// The point at `length` from `anchor` toward `target`; when target sits on the
// anchor, fall back to the original (unmoved) direction, then to +x.
Vec3 place_at_distance(const Vec3& anchor, const Vec3& target, const Vec3& fallback_direction, Real length) {
  Vec3 direction = target - anchor;
  Real norm = direction.norm();
  if (!(norm > 0)) {
    direction = fallback_direction;
    norm = direction.norm();
  }
  if (!(norm > 0)) return anchor + length * Vec3::UnitX();
  return anchor + (length / norm) * direction;
}

// docs/algorithms.md §1.5: from the moved point, toward the head, then toward the tail.
Vec3List seed_pass(const Vec3List& points, const std::vector<Real>& rest_lengths, long moved_index, Real scale) {
  const long n = static_cast<long>(points.size());
  Vec3List out = points;
  for (long i = moved_index - 1; i >= 0; --i) {
    out[i] = place_at_distance(out[i + 1], points[i], points[i] - points[i + 1], scale * rest_lengths[i]);
  }
  for (long i = moved_index + 1; i < n; ++i) {
    out[i] = place_at_distance(out[i - 1], points[i], points[i] - points[i - 1], scale * rest_lengths[i - 1]);
  }
  return out;
}

}  // namespace

Vec3List preserve_lengths(const Vec3List& points, const std::vector<Real>& rest_lengths, long moved_index,
                          std::optional<Real> arc_length) {
  const long n = static_cast<long>(points.size());
  if (n < 2) throw std::invalid_argument("points needs at least 2 points");
  for (const Vec3& p : points) {
    if (!p.allFinite()) throw std::invalid_argument("points contains NaN or inf");
  }
  if (static_cast<long>(rest_lengths.size()) != n - 1) {
    throw std::invalid_argument("rest_lengths must have one length per segment (" + std::to_string(n - 1) + ")");
  }
  for (Real length : rest_lengths) {
    if (!(std::isfinite(length) && length > 0)) throw std::invalid_argument("rest_lengths must be finite and > 0");
  }
  if (moved_index < 0 || moved_index >= n) {
    throw std::invalid_argument("moved_index must lie in [0, " + std::to_string(n - 1) + "]");
  }
  if (arc_length && !(std::isfinite(*arc_length) && *arc_length > 0)) {
    throw std::invalid_argument("arc_length must be finite and > 0");
  }
  if (arc_length && n < 4) throw std::invalid_argument("points needs at least 4 points to measure arc_length");
  Vec3List out = seed_pass(points, rest_lengths, moved_index, 1);
  if (!arc_length) return out;
  // Arc length is nearly proportional to the common scale: s <- s * target / current.
  Real scale = 1;
  for (int step = 0; step < 12; ++step) {
    const Real current = curve_length(CubicBSpline(out));
    if (std::abs(current - *arc_length) <= Real(1e-9) * *arc_length) break;
    scale *= *arc_length / current;
    out = seed_pass(points, rest_lengths, moved_index, scale);
  }
  return out;
}

Vec3List preserve_lengths_from_head(const Vec3List& points, const std::vector<Real>& rest_lengths,
                                    std::optional<Real> arc_length) {
  return preserve_lengths(points, rest_lengths, 0, arc_length);
}

}  // namespace kodawari::ffd
