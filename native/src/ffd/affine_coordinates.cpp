#include "kodawari/ffd/affine_coordinates.hpp"

namespace kodawari::ffd {

void fill_affine_coordinates(const AffineCoordinates& affine, const float* vertices, std::size_t count,
                             float* packed) {
  for (int k = 0; k < 3; ++k) {
    if (!affine.holds[k]) continue;
    const AffineRow& row = affine.rows[k];
    for (std::size_t i = 0; i < count; ++i) packed[3 * i + k] = affine_value(row, vertices + 3 * i);
  }
}

}  // namespace kodawari::ffd
