// The control-axis FFD (docs/algorithms.md §1, Yamanogue's axial deformation): bind a mesh to
// a control curve once, then rebuild it from any new pose of the curve.
#pragma once

#include <cstddef>
#include <optional>
#include <vector>

#include "kodawari/common.hpp"
#include "kodawari/ffd/affine_coordinates.hpp"
#include "kodawari/ffd/bspline.hpp"
#include "kodawari/ffd/frame_table.hpp"
#include "kodawari/ffd/frames.hpp"
#include "kodawari/ffd/sampled_curve.hpp"

namespace kodawari::ffd {

// Throws std::invalid_argument naming "twist" unless it is empty or holds
// `count` finite values.
void validate_twist(const std::vector<Real>& twist, int count);

// Frames of the curve of `control_points` at `samples` evenly spaced t; the
// start e2 comes from `up` when given, else from default_start_normal.
FrameList axis_frames(const Vec3List& control_points, const std::vector<Real>& twist, const std::optional<Vec3>& up,
                      int samples);

class AxisBinding {
 public:
  // vertices: `count` packed float xyz triples. Throws std::invalid_argument
  // (naming the argument) on bad input.
  AxisBinding(const Vec3List& control_points, const float* vertices, std::size_t count,
              const std::vector<Real>& twist, const std::optional<Vec3>& up, unsigned threads = 0);

  std::size_t count() const { return count_; }
  int control_point_count() const { return control_point_count_; }
  const std::vector<AxisCoordinate>& coordinates() const { return coordinates_; }
  float parameter(std::size_t i) const;  // t in [0, 1]

  // Writes count() deformed xyz triples to `out`. Allocates only the fixed-size
  // frame table; every vertex is computed by one thread with the same
  // arithmetic, so the result does not depend on `threads` (0 = all cores).
  // Every written position is finite: a curve whose frames would not give finite
  // positions throws std::invalid_argument before `out` is touched (so `out` may be
  // memory the user sees, e.g. a shape key, without a half-written frame).
  void deform(const Vec3List& control_points, const std::vector<Real>& twist, const std::optional<Vec3>& up,
              float* out, unsigned threads = 0) const;

  // The frame table deform() would use for these control points (same checks, same
  // arithmetic): what a deformer outside the core (a Geometry Nodes modifier,
  // docs/algorithms.md §1.6) needs per frame to give deform()'s positions.
  void frame_table(const Vec3List& control_points, const std::vector<Real>& twist, const std::optional<Vec3>& up,
                   FrameTable& table) const;

  // Each vertex's coordinates packed into three floats (docs/algorithms.md §1.6):
  // (s, u, v) with s = segment + fraction inside the table and, for a vertex beyond an
  // end (the only ones with w != 0), s = w * end_scale before the head or
  // kTableSegments + w * end_scale after the tail. Writes 3 * count() floats.
  void packed_coordinates(float end_scale, float* out) const;

  // Which packed coordinates (s, u, v) are an affine function of the rest position
  // (docs/algorithms.md §1.6): rows derived from the rest axis (its start frame and its span
  // along the start tangent), each kept only if it gives that coordinate of every one of the
  // bound `vertices` (the rest positions bound, `count` xyz triples) to within `tolerance`
  // body lengths, evaluated in float as affine_value does. Throws std::logic_error once
  // released.
  AffineCoordinates affine_coordinates(const float* vertices, std::size_t count, float end_scale,
                                       double tolerance) const;

  // Frees the per-vertex coordinates (20 bytes per vertex) once they live elsewhere (the
  // packed attribute of the Blender mesh): frame_table() still works; deform() and
  // packed_coordinates() then throw std::logic_error (use deform_packed).
  void release_coordinates();
  bool released() const { return released_; }

 private:
  int control_point_count_ = 0;
  UniformCurveSampler sampler_;
  Vec3 rest_tangent_ = Vec3::UnitX();
  Vec3 rest_normal_ = Vec3::UnitY();
  std::vector<AxisCoordinate> coordinates_;
  std::array<AffineRow, 3> rest_rows_{};  // s, u, v as n . P + c if the rest axis were straight
  float reach_ = 0;  // the largest |u|, |v|, |w| bound: with the frame table it bounds |P'|
  bool released_ = false;
  std::size_t count_ = 0;
};

// deform() from packed coordinates (AxisBinding::packed_coordinates, the same end_scale)
// and a frame table (AxisBinding::frame_table): `count` xyz triples into `out`, the same
// arithmetic per vertex as deform() (docs/algorithms.md §1.6).
void deform_packed(const FrameTable& table, const float* packed, std::size_t count, float end_scale, float* out,
                   unsigned threads = 0);

}  // namespace kodawari::ffd
