#include "kodawari/ffd/frame_table.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::ffd {

void fill_frame_table(const FrameList& frames, std::vector<TableSegment>& table) {
  table.resize(kTableSegments);
  for (int i = 0; i < kTableSegments; ++i) {
    const Frame& a = frames[static_cast<std::size_t>(i)];
    const Frame& b = frames[static_cast<std::size_t>(i) + 1];
    TableSegment& s = table[static_cast<std::size_t>(i)];
    for (int k = 0; k < 3; ++k) {
      s.origin[k] = static_cast<float>(a.origin[k]);
      s.d_origin[k] = static_cast<float>(b.origin[k] - a.origin[k]);
      s.e1[k] = static_cast<float>(a.e1[k]);
      s.d_e1[k] = static_cast<float>(b.e1[k] - a.e1[k]);
      s.e2[k] = static_cast<float>(a.e2[k]);
      s.d_e2[k] = static_cast<float>(b.e2[k] - a.e2[k]);
      s.e3[k] = static_cast<float>(a.e3[k]);
      s.d_e3[k] = static_cast<float>(b.e3[k] - a.e3[k]);
    }
  }
}

void locate_in_table(Real t, std::uint32_t& segment, float& fraction) {
  const Real x = std::clamp(t, Real(0), Real(1)) * kTableSegments;
  const int i = std::min(static_cast<int>(std::floor(x)), kTableSegments - 1);
  segment = static_cast<std::uint32_t>(i);
  fraction = static_cast<float>(x - i);
}

}  // namespace kodawari::ffd
