// A dense table of frames at evenly spaced t, stored in float as value + delta
// per segment, so one vertex costs one table read and a few multiply-adds.
// Linear interpolation between 1024 segments keeps the origin within ~1e-6 of
// the body length of the exact curve even for a full-circle bend.
#pragma once

#include <cstdint>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/ffd/frames.hpp"

namespace kodawari::ffd {

constexpr int kTableSegments = 1024;

struct TableSegment {
  // origin, e1, e2, e3 at the segment start, then their change across the segment
  float origin[3], d_origin[3], e1[3], d_e1[3], e2[3], d_e2[3], e3[3], d_e3[3];
};

// Where a vertex sits: segment, fraction in it, and its offsets in the frame.
struct AxisCoordinate {
  std::uint32_t segment;
  float fraction, u, v, w;
};

// Fills `table` (resized to kTableSegments, no growth after the first call)
// from kTableSegments + 1 frames.
void fill_frame_table(const FrameList& frames, std::vector<TableSegment>& table);

// The segment and fraction of parameter t in [0, 1].
void locate_in_table(Real t, std::uint32_t& segment, float& fraction);

// Interpolated frame at (segment, fraction), in the exact float arithmetic the
// deform uses, so that bind's offsets rebuild the rest mesh.
inline void table_frame(const TableSegment& s, float f, float origin[3], float e1[3], float e2[3], float e3[3]) {
  for (int k = 0; k < 3; ++k) {
    origin[k] = s.origin[k] + f * s.d_origin[k];
    e1[k] = s.e1[k] + f * s.d_e1[k];
    e2[k] = s.e2[k] + f * s.d_e2[k];
    e3[k] = s.e3[k] + f * s.d_e3[k];
  }
}

// P' = M(t) + u e2 + v e3 + w e1 (SEEDS §1 eq. 3.2, plus w beyond the ends).
inline void deform_vertex(const TableSegment& s, const AxisCoordinate& c, float* out) {
  float origin[3], e1[3], e2[3], e3[3];
  table_frame(s, c.fraction, origin, e1, e2, e3);
  for (int k = 0; k < 3; ++k) out[k] = origin[k] + c.u * e2[k] + c.v * e3[k] + c.w * e1[k];
}

}  // namespace kodawari::ffd
