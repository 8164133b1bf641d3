// Keeping control-point distances so the body does not stretch (docs/algorithms.md
// §1.5), and the rest lengths they keep.
#pragma once

#include <optional>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::ffd {

// |P(i+1) - P(i)| for i = 0..n-2.
std::vector<Real> segment_lengths(const Vec3List& points);

// The seed's pass: keep points[moved_index]; walking toward the head, put each
// point on the segment from itself toward its already placed tail-side
// neighbour at the rest distance; then the same toward the tail.
// Keeping the polygon's lengths keeps the B-spline's arc length only roughly:
// a bent curve cuts its corners (about 0.5% shorter for a tail swing of 0.1 of
// the body with 8 points, 1.5% at 0.2). Given `arc_length` (>= 4 points), all
// rest lengths are then scaled by one common factor, found by a few fixed-point
// steps, until the curve's arc length matches it to 1e-9.
// Throws std::invalid_argument naming the argument on bad input.
Vec3List preserve_lengths(const Vec3List& points, const std::vector<Real>& rest_lengths, long moved_index,
                          std::optional<Real> arc_length = std::nullopt);

// Pins point 0 and propagates tailward (the swim drives every point each frame).
Vec3List preserve_lengths_from_head(const Vec3List& points, const std::vector<Real>& rest_lengths,
                                    std::optional<Real> arc_length = std::nullopt);

}  // namespace kodawari::ffd
