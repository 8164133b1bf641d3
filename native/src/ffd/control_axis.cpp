#include "kodawari/ffd/control_axis.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "kodawari/ffd/closest_point.hpp"
#include "kodawari/parallel.hpp"

namespace kodawari::ffd {

namespace {
// Below this many vertices per thread, spawning threads costs more than it saves.
constexpr std::size_t kMinVerticesPerThread = 16384;
constexpr std::size_t kMinBindVerticesPerThread = 512;
}  // namespace

void validate_twist(const std::vector<Real>& twist, int count) {
  if (twist.empty()) return;
  if (static_cast<int>(twist.size()) != count) {
    throw std::invalid_argument("twist must have one value per control point (" + std::to_string(count) + ")");
  }
  for (Real value : twist) {
    if (!std::isfinite(value)) throw std::invalid_argument("twist contains NaN or inf");
  }
}

FrameList axis_frames(const CubicBSpline& curve, const std::vector<Real>& twist, const std::optional<Vec3>& up,
                      int samples) {
  validate_twist(twist, curve.count());
  const Vec3 tangent = unit_tangent(curve, 0);
  const Vec3 normal = up ? start_normal_from_up(*up, tangent) : default_start_normal(tangent);
  return rotation_minimising_frames(curve, twist, normal, samples);
}

AxisBinding::AxisBinding(const Vec3List& control_points, const float* vertices, std::size_t count,
                         const std::vector<Real>& twist, const std::optional<Vec3>& up, unsigned threads) {
  if (count == 0) throw std::invalid_argument("vertices must not be empty");
  for (std::size_t i = 0; i < 3 * count; ++i) {
    if (!std::isfinite(vertices[i])) throw std::invalid_argument("vertices contains NaN or inf");
  }
  const CubicBSpline curve(control_points);
  control_point_count_ = curve.count();
  const FrameList frames = axis_frames(curve, twist, up, kTableSegments + 1);
  rest_tangent_ = frames.front().e1;
  // The start normal before twist: undo the start twist's roll.
  const Real start_roll = twist.empty() ? Real(0) : curve.blend(twist, 0);
  rest_normal_ = std::cos(start_roll) * frames.front().e2 - std::sin(start_roll) * frames.front().e3;
  std::vector<TableSegment> table;
  fill_frame_table(frames, table);
  const ClosestPointFinder finder(curve);

  coordinates_.resize(count);
  parallel_for(count, threads, kMinBindVerticesPerThread, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 p(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
      const Real t = finder.parameter(p);
      AxisCoordinate& c = coordinates_[i];
      locate_in_table(t, c.segment, c.fraction);
      float of[3], e1f[3], e2f[3], e3f[3];
      table_frame(table[c.segment], c.fraction, of, e1f, e2f, e3f);
      const Vec3 d = p - Vec3(of[0], of[1], of[2]);
      const Vec3 e1(e1f[0], e1f[1], e1f[2]), e2(e2f[0], e2f[1], e2f[2]), e3(e3f[0], e3f[1], e3f[2]);
      if (t <= 0 || t >= 1) {
        // Beyond an end: keep the full offset in the end frame, so the part
        // past the axis (snout, fin tip) follows the end rigidly.
        Mat3 basis;
        basis << e1, e2, e3;
        const Vec3 uvw = basis.inverse() * d;
        c.w = static_cast<float>(uvw[0]);
        c.u = static_cast<float>(uvw[1]);
        c.v = static_cast<float>(uvw[2]);
      } else {
        // MP is perpendicular to e1 at the closest point (eq. 3.1); the
        // interpolated (e2, e3) are unit and orthogonal only to ~1e-6, so
        // solve the 2x2 normal equations instead of projecting.
        const Real a = e2.dot(e2), b = e2.dot(e3), cc = e3.dot(e3);
        const Real r2 = d.dot(e2), r3 = d.dot(e3);
        const Real det = a * cc - b * b;
        c.u = static_cast<float>((r2 * cc - r3 * b) / det);
        c.v = static_cast<float>((r3 * a - r2 * b) / det);
        c.w = 0.0f;
      }
    }
  });
}

float AxisBinding::parameter(std::size_t i) const {
  const AxisCoordinate& c = coordinates_[i];
  return static_cast<float>((Real(c.segment) + Real(c.fraction)) / kTableSegments);
}

void AxisBinding::deform(const Vec3List& control_points, const std::vector<Real>& twist,
                         const std::optional<Vec3>& up, float* out, unsigned threads) const {
  const CubicBSpline curve(control_points);
  if (curve.count() != control_point_count_) {
    throw std::invalid_argument("control_points must have " + std::to_string(control_point_count_) +
                                " points, as at bind time");
  }
  validate_twist(twist, curve.count());
  const Vec3 tangent = unit_tangent(curve, 0);
  // Without `up`, the rest start frame follows the start tangent by the
  // smallest rotation, so a pure translation or bend never rolls the body.
  const Vec3 normal = up ? start_normal_from_up(*up, tangent) : carry_normal(rest_normal_, rest_tangent_, tangent);
  const FrameList frames = rotation_minimising_frames(curve, twist, normal, kTableSegments + 1);
  std::vector<TableSegment> table;
  fill_frame_table(frames, table);

  const AxisCoordinate* coords = coordinates_.data();
  const TableSegment* segments = table.data();
  parallel_for(coordinates_.size(), threads, kMinVerticesPerThread, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) deform_vertex(segments[coords[i].segment], coords[i], out + 3 * i);
  });
}

}  // namespace kodawari::ffd
