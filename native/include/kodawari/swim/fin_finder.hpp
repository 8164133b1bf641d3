// Automatic fin finder (docs/algorithms.md §2.8): fins are the
// parts of a fish mesh that stand out of the body's cross-section.
//
// Each vertex is placed in the cross-section of the body axis nearest to it
// (arc fraction s, offsets across). Per slice along the axis, the outermost
// point of the mesh in each angular sector outlines the cross-section; an
// axis-aligned ellipse fitted to that outline, with the sectors far outside
// the fit dropped and the fit repeated, is the body's core (a fin fills only a
// few sectors, so it cannot pull the fit out; a mouth or lips lie inside the
// outline, so they never count). A vertex well outside its slice's core is a
// fin candidate; candidates connected by mesh edges form fins, named by where
// they sit (behind the body: caudal; above: dorsal; below: pelvic or anal;
// at the sides: pectoral). Everything is O(vertices + edges), no ray casting.
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

#include "kodawari/common.hpp"

namespace kodawari::swim {

enum class FinKind : std::int8_t { None = 0, Caudal = 1, Dorsal = 2, Anal = 3, Pelvic = 4, Pectoral = 5 };

struct FinFinderOptions {
  int slices = 48;             // cross-sections along the axis
  int sectors = 32;            // angular sectors per cross-section
  Real outside = 1.2;          // a candidate lies this many core radii (or more) from the core's centre...
  Real margin = 0.004;         // ...and at least this far (fraction of body length) outside the core
  Real max_aspect = 5.0;       // a core flatter than this is a fin plate (caudal fin, flukes), not body
  std::size_t min_vertices = 8;  // smaller connected candidate sets are noise
};

// The axis as a polyline (>= 2 points, snout first) and the body's up direction.
// Writes, for vertices [begin, end), (s, side, up) triples into `out` (3 floats per
// vertex, indexed like the vertices): s = arc fraction of the closest axis point,
// clamped to [0, 1]; side, up = the offset across the axis there, in body lengths.
void fin_axis_coordinates(const Vec3List& axis, const Vec3& up, const float* vertices, std::size_t begin,
                          std::size_t end, float* out, unsigned threads = 0);

struct SliceCore {
  bool has_core = false;     // false: the slice holds fin only (e.g. a forked caudal fin)
  Real centre_side = 0, centre_up = 0, half_side = 0, half_up = 0;
};

// The core ellipse of each slice from (s, side, up) coordinates and mesh edges
// (pairs of vertex indices; long edges are sampled so a low-poly outline is whole).
std::vector<SliceCore> fin_slice_cores(const float* coordinates, std::size_t count, const std::int32_t* edges,
                                       std::size_t edge_count, const FinFinderOptions& options);

// One FinKind per vertex (None for the body). Throws std::invalid_argument on an
// edge index out of range.
std::vector<std::int8_t> find_fins(const float* coordinates, std::size_t count, const std::int32_t* edges,
                                   std::size_t edge_count, const FinFinderOptions& options);

}  // namespace kodawari::swim
