// Packed coordinates that are an affine function of the rest position (docs/algorithms.md
// §1.6): where the rest axis makes one of (s, u, v) equal n . P + c for every vertex, a
// deformer outside the core can compute it from the rest position instead of storing it.
#pragma once

#include <array>
#include <cstddef>

namespace kodawari::ffd {

// One packed coordinate as n . P + c: (n.x, n.y, n.z, c), in float as a deformer uses it.
using AffineRow = std::array<float, 4>;

struct AffineCoordinates {
  std::array<AffineRow, 3> rows{};  // for s, u, v
  std::array<bool, 3> holds{};      // the row gives that coordinate of every vertex within the bound
  std::array<double, 3> worst{};    // its largest miss, in body lengths (s's segments scaled by L / 1024)
};

// n . P + c in float; the Fish Swim nodes compute the same up to float rounding (a Dot Product,
// or one component of P for an object axis, with c folded into the frame table).
inline float affine_value(const AffineRow& row, const float* p) {
  return (row[0] * p[0] + row[1] * p[1] + row[2] * p[2]) + row[3];
}

// Writes coordinate k of `packed` (count x 3 floats) from the vertices' rest positions for every
// k whose row holds; the other columns are left as they are.
void fill_affine_coordinates(const AffineCoordinates& affine, const float* vertices, std::size_t count,
                             float* packed);

}  // namespace kodawari::ffd
