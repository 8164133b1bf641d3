#include "kodawari/ffd/control_axis.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

#include "kodawari/ffd/closest_point.hpp"
#include "kodawari/parallel.hpp"
#include "kodawari/worker_pool.hpp"

namespace kodawari::ffd {

namespace {
// Vertices per chunk a deform thread takes at a time (worker_pool.hpp: threads kept for the
// process, the caller never waiting for one that has not started).
constexpr std::size_t kDeformGrain = 32768;
constexpr std::size_t kMinBindVerticesPerThread = 512;

// The deformer's curve is the table's interpolated one, which differs from the
// exact spline by up to ~5e-6 of the length (mostly along the tangent, as the
// parameter speed varies). Moving t to where P - O(t) is perpendicular to the
// interpolated e1 makes the rest rebuild exact up to float rounding.
void refine_on_table(const FrameTable& table, const Vec3& p, std::uint32_t& segment, float& fraction) {
  Real f = fraction;
  int s = static_cast<int>(segment);
  for (int hop = 0; hop < 4; ++hop) {
    const TableSegment& seg = table[static_cast<std::size_t>(s)];
    const Vec3 o = seg.origin.head<3>().cast<Real>(), d_o = seg.d_origin.head<3>().cast<Real>();
    const Vec3 e1 = seg.e1.head<3>().cast<Real>(), d_e1 = seg.d_e1.head<3>().cast<Real>();
    for (int iteration = 0; iteration < 4; ++iteration) {
      const Vec3 r = p - o - f * d_o;
      const Vec3 tangent = e1 + f * d_e1;
      const Real g = r.dot(tangent);
      const Real slope = -d_o.dot(tangent) + r.dot(d_e1);
      if (!(slope < 0)) break;  // not a minimum of the distance here: keep f
      f -= g / slope;
    }
    if (f < 0 && s > 0) {
      --s;
      f = 1;
    } else if (f > 1 && s < kTableSegments - 1) {
      ++s;
      f = 0;
    } else {
      break;
    }
  }
  segment = static_cast<std::uint32_t>(s);
  fraction = static_cast<float>(std::clamp(f, Real(0), Real(1)));
}

// Throws unless every position deform_vertex can make from this table and coordinates no
// larger than `reach` is finite: each lane is at most 2 A (1 + 3 reach), A the largest
// table entry, and that stays well inside float's range.
void require_finite_positions(const FrameTable& table, float reach) {
  double largest = 0;
  bool finite = true;
  for (const TableSegment& s : table) {
    for (const Vec4f* v : {&s.origin, &s.d_origin, &s.e1, &s.d_e1, &s.e2, &s.d_e2, &s.e3, &s.d_e3}) {
      finite = finite && v->allFinite();
      largest = std::max(largest, double(v->cwiseAbs().maxCoeff()));
    }
  }
  if (!finite || !(2.0 * largest * (1.0 + 3.0 * double(reach)) < 1e36)) {
    throw std::invalid_argument(
        "control_points: the curve is too close to degenerate to deform the mesh (non-finite positions); "
        "spread the points apart");
  }
}

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

FrameList axis_frames(const Vec3List& control_points, const std::vector<Real>& twist, const std::optional<Vec3>& up,
                      int samples) {
  validate_control_points(control_points, "control_points");
  validate_twist(twist, static_cast<int>(control_points.size()));
  CurveSamples sampled;
  UniformCurveSampler(static_cast<int>(control_points.size()), samples).sample(control_points, twist, sampled);
  const Vec3& tangent = sampled.tangent.front();
  FrameList frames;
  rotation_minimising_frames(sampled, up ? start_normal_from_up(*up, tangent) : default_start_normal(tangent), frames);
  return frames;
}

namespace {
int checked_count(const Vec3List& control_points) {
  validate_control_points(control_points, "control_points");
  return static_cast<int>(control_points.size());
}
}  // namespace

AxisBinding::AxisBinding(const Vec3List& control_points, const float* vertices, std::size_t count,
                         const std::vector<Real>& twist, const std::optional<Vec3>& up, unsigned threads)
    : control_point_count_(checked_count(control_points)), sampler_(control_point_count_, kTableSegments + 1) {
  validate_twist(twist, control_point_count_);
  if (count == 0) throw std::invalid_argument("vertices must not be empty");
  for (std::size_t i = 0; i < 3 * count; ++i) {
    if (!std::isfinite(vertices[i])) throw std::invalid_argument("vertices contains NaN or inf");
  }
  const CubicBSpline curve(control_points);
  CurveSamples sampled;
  sampler_.sample(control_points, twist, sampled);
  rest_tangent_ = sampled.tangent.front();
  rest_normal_ = up ? start_normal_from_up(*up, rest_tangent_) : default_start_normal(rest_tangent_);
  FrameList frames;
  rotation_minimising_frames(sampled, rest_normal_, frames);
  FrameTable table;
  fill_frame_table(frames, table);
  const ClosestPointFinder finder(curve);
  {
    // Along a straight rest axis with the frames of its start, s, u and v would be affine in
    // P: u = e2 . (P - O0), v = e3 . (P - O0), s = 1024 e1 . (P - O0) / span. Whether they are
    // is decided on the vertices (affine_coordinates), never assumed.
    const TableSegment& first = table.front();
    const TableSegment& last = table.back();
    const Vec3 o0 = first.origin.head<3>().cast<Real>();
    const Vec3 o1 = (last.origin + last.d_origin).head<3>().cast<Real>();
    const Vec3 e1 = first.e1.head<3>().cast<Real>();
    const auto row = [&](const Vec3& n) {
      return AffineRow{float(n.x()), float(n.y()), float(n.z()), float(-n.dot(o0))};
    };
    const Real span = e1.dot(o1 - o0);
    rest_rows_[0] = span > 0 ? row(e1 * (Real(kTableSegments) / span)) : AffineRow{};
    rest_rows_[1] = row(first.e2.head<3>().cast<Real>());
    rest_rows_[2] = row(first.e3.head<3>().cast<Real>());
  }

  coordinates_.resize(count);
  parallel_for(count, threads, kMinBindVerticesPerThread, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const Vec3 p(vertices[3 * i], vertices[3 * i + 1], vertices[3 * i + 2]);
      const Real t = finder.parameter(p);
      AxisCoordinate& c = coordinates_[i];
      locate_in_table(t, c.segment, c.fraction);
      if (t > 0 && t < 1) refine_on_table(table, p, c.segment, c.fraction);
      const bool at_head = c.segment == 0 && c.fraction == 0.0f;
      const bool at_tail = c.segment == kTableSegments - 1 && c.fraction == 1.0f;
      const TableFrame frame = table_frame(table[c.segment], c.fraction);
      const Vec3 d = p - frame.origin.head<3>().cast<Real>();
      const Vec3 e1 = frame.e1.head<3>().cast<Real>(), e2 = frame.e2.head<3>().cast<Real>(),
                 e3 = frame.e3.head<3>().cast<Real>();
      if (at_head || at_tail) {
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
  for (const AxisCoordinate& c : coordinates_) {
    reach_ = std::max({reach_, std::abs(c.u), std::abs(c.v), std::abs(c.w)});
  }
  count_ = count;
}

void AxisBinding::release_coordinates() {
  std::vector<AxisCoordinate>().swap(coordinates_);
  released_ = true;
}

float AxisBinding::parameter(std::size_t i) const {
  if (released_) throw std::logic_error("the binding's coordinates were released");
  const AxisCoordinate& c = coordinates_[i];
  return static_cast<float>((Real(c.segment) + Real(c.fraction)) / kTableSegments);
}

void AxisBinding::frame_table(const Vec3List& control_points, const std::vector<Real>& twist,
                              const std::optional<Vec3>& up, FrameTable& table) const {
  validate_control_points(control_points, "control_points");
  if (static_cast<int>(control_points.size()) != control_point_count_) {
    throw std::invalid_argument("control_points must have " + std::to_string(control_point_count_) +
                                " points, as at bind time");
  }
  validate_twist(twist, control_point_count_);
  CurveSamples sampled;
  sampler_.sample(control_points, twist, sampled);
  const Vec3& tangent = sampled.tangent.front();
  // Without `up`, the rest start frame follows the start tangent by the
  // smallest rotation, so a pure translation or bend never rolls the body.
  const Vec3 normal = up ? start_normal_from_up(*up, tangent) : carry_normal(rest_normal_, rest_tangent_, tangent);
  FrameList frames;
  rotation_minimising_frames(sampled, normal, frames);
  fill_frame_table(frames, table);
  require_finite_positions(table, reach_);
}

namespace {
float packed_s(const AxisCoordinate& c, float end_scale) {
  float s = static_cast<float>(c.segment) + c.fraction;
  if (c.w != 0.0f) {
    // Only a vertex at an end has w != 0: before the head w <= 0 (its closest curve
    // point is the head, so it lies behind the head's tangent plane), after the
    // tail w >= 0. The sign keeps s outside [0, kTableSegments], where the reader
    // finds w again as (s - clamp(s)) / end_scale.
    const bool head = c.segment == 0 && c.fraction == 0.0f;
    s = head ? std::min(c.w, 0.0f) * end_scale : float(kTableSegments) + std::max(c.w, 0.0f) * end_scale;
  }
  return s;
}
}  // namespace

void AxisBinding::packed_coordinates(float end_scale, float* out) const {
  if (released_) throw std::logic_error("the binding's coordinates were released");
  for (std::size_t i = 0; i < coordinates_.size(); ++i) {
    const AxisCoordinate& c = coordinates_[i];
    out[3 * i] = packed_s(c, end_scale);
    out[3 * i + 1] = c.u;
    out[3 * i + 2] = c.v;
  }
}

AffineCoordinates AxisBinding::affine_coordinates(const float* vertices, std::size_t count, float end_scale,
                                                  double tolerance) const {
  if (released_) throw std::logic_error("the binding's coordinates were released");
  if (count != count_) throw std::invalid_argument("vertices must be the bound rest positions");
  AffineCoordinates affine;
  affine.rows = rest_rows_;
  // Misses in body lengths: s counts 1024 segments per body length, u and v are lengths.
  const double length = double(kTableSegments) / double(end_scale);
  const double per_unit[3] = {1.0 / kTableSegments, 1.0 / length, 1.0 / length};
  for (std::size_t i = 0; i < count; ++i) {
    const AxisCoordinate& c = coordinates_[i];
    const float bound[3] = {packed_s(c, end_scale), c.u, c.v};
    for (int k = 0; k < 3; ++k) {
      const double miss = std::abs(double(affine_value(rest_rows_[k], vertices + 3 * i)) - double(bound[k]));
      // A non-finite row (a degenerate axis) never holds.
      affine.worst[k] = std::isfinite(miss) ? std::max(affine.worst[k], miss * per_unit[k]) : HUGE_VAL;
    }
  }
  for (int k = 0; k < 3; ++k) affine.holds[k] = affine.worst[k] <= tolerance;
  return affine;
}

void AxisBinding::deform(const Vec3List& control_points, const std::vector<Real>& twist,
                         const std::optional<Vec3>& up, float* out, unsigned threads) const {
  if (released_) throw std::logic_error("the binding's coordinates were released: deform the packed ones");
  FrameTable table;
  frame_table(control_points, twist, up, table);

  const AxisCoordinate* coords = coordinates_.data();
  const TableSegment* segments = table.data();
  parallel_chunks(coordinates_.size(), threads, kDeformGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) deform_vertex(segments[coords[i].segment], coords[i], out + 3 * i);
  });
}

void deform_packed(const FrameTable& table, const float* packed, std::size_t count, float end_scale, float* out,
                   unsigned threads) {
  const float inverse_scale = 1.0f / end_scale;
  const float last = float(kTableSegments);
  parallel_chunks(count, threads, kDeformGrain, [&](std::size_t begin, std::size_t end) {
    for (std::size_t i = begin; i < end; ++i) {
      const float s = packed[3 * i];
      const float t = std::clamp(s, 0.0f, last);
      // t >= 0, so truncation is the floor (std::floor is a libm call on baseline x86-64).
      const std::uint32_t whole = std::min<std::uint32_t>(static_cast<std::uint32_t>(t), kTableSegments - 1);
      const float segment = static_cast<float>(whole);
      AxisCoordinate c;
      c.segment = whole;
      c.fraction = t - segment;
      c.u = packed[3 * i + 1];
      c.v = packed[3 * i + 2];
      c.w = (s - t) * inverse_scale;
      deform_vertex(table[c.segment], c, out + 3 * i);
    }
  });
}

}  // namespace kodawari::ffd
