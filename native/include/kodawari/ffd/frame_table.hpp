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

// xyz in the first three lanes, 0 in the fourth: one SSE register per vector.
using Vec4f = Eigen::Vector4f;

struct TableSegment {
  EIGEN_MAKE_ALIGNED_OPERATOR_NEW
  // origin and e1..e3 at the segment start, then their change across the segment
  Vec4f origin, d_origin, e1, d_e1, e2, d_e2, e3, d_e3;
};
using FrameTable = std::vector<TableSegment, Eigen::aligned_allocator<TableSegment>>;

// Where a vertex sits: segment, fraction in it, and its offsets in the frame.
struct AxisCoordinate {
  std::uint32_t segment;
  float fraction, u, v, w;
};

// Fills `table` (resized to kTableSegments, no growth after the first call)
// from kTableSegments + 1 frames.
void fill_frame_table(const FrameList& frames, FrameTable& table);

// The segment and fraction of parameter t in [0, 1].
void locate_in_table(Real t, std::uint32_t& segment, float& fraction);

struct TableFrame {
  Vec4f origin, e1, e2, e3;
};

// Interpolated frame at (segment, fraction), in float like the deform.
inline TableFrame table_frame(const TableSegment& s, float f) {
  return {s.origin + f * s.d_origin, s.e1 + f * s.d_e1, s.e2 + f * s.d_e2, s.e3 + f * s.d_e3};
}

// Inlined into every per-vertex loop: a call per vertex (its coordinate passed through
// memory) cost 2-3x the arithmetic (bench_ffd, DeformPacked).
#if defined(__GNUC__) || defined(__clang__)
#define KODAWARI_ALWAYS_INLINE inline __attribute__((always_inline))
#elif defined(_MSC_VER)
#define KODAWARI_ALWAYS_INLINE __forceinline
#else
#define KODAWARI_ALWAYS_INLINE inline
#endif
// P' = M(t) + u e2 + v e3 + w e1 (docs/algorithms.md §1.4, plus w beyond the ends),
// with the frame interpolated linearly within the segment. Four-lane float
// arithmetic, the same for every vertex whichever thread computes it.
KODAWARI_ALWAYS_INLINE void deform_vertex(const TableSegment& s, const AxisCoordinate& c, float* out) {
  const float f = c.fraction;
  const Vec4f p = (s.origin + c.u * s.e2 + c.v * s.e3 + c.w * s.e1) +
                  f * (s.d_origin + c.u * s.d_e2 + c.v * s.d_e3 + c.w * s.d_e1);
  out[0] = p[0];
  out[1] = p[1];
  out[2] = p[2];
}

}  // namespace kodawari::ffd
