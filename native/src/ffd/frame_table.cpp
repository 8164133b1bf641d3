#include "kodawari/ffd/frame_table.hpp"

#include <algorithm>
#include <cmath>

namespace kodawari::ffd {

namespace {
Vec4f lanes(const Vec3& v) { return Vec4f(float(v.x()), float(v.y()), float(v.z()), 0.0f); }
Vec4f lane_delta(const Vec3& from, const Vec3& to) { return lanes(Vec3(to - from)); }
}  // namespace

void fill_frame_table(const FrameList& frames, FrameTable& table) {
  table.resize(kTableSegments);
  for (int i = 0; i < kTableSegments; ++i) {
    const Frame& a = frames[static_cast<std::size_t>(i)];
    const Frame& b = frames[static_cast<std::size_t>(i) + 1];
    TableSegment& s = table[static_cast<std::size_t>(i)];
    s.origin = lanes(a.origin);
    s.d_origin = lane_delta(a.origin, b.origin);
    s.e1 = lanes(a.e1);
    s.d_e1 = lane_delta(a.e1, b.e1);
    s.e2 = lanes(a.e2);
    s.d_e2 = lane_delta(a.e2, b.e2);
    s.e3 = lanes(a.e3);
    s.d_e3 = lane_delta(a.e3, b.e3);
  }
}

void locate_in_table(Real t, std::uint32_t& segment, float& fraction) {
  const Real x = std::clamp(t, Real(0), Real(1)) * kTableSegments;
  const int i = std::min(static_cast<int>(std::floor(x)), kTableSegments - 1);
  segment = static_cast<std::uint32_t>(i);
  fraction = static_cast<float>(x - i);
}

}  // namespace kodawari::ffd
