// Python face of the control-axis FFD; the algorithm is docs/algorithms.md §1. Thin: checks
// arrays (ValueError naming the argument), converts, releases the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#if defined(__GLIBC__)
#include <malloc.h>
#endif
#include <optional>
#include <stdexcept>
#include <vector>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/ffd/bspline.hpp"
#include "kodawari/ffd/control_axis.hpp"
#include "kodawari/ffd/frame_table.hpp"
#include "kodawari/ffd/frames.hpp"
#include "kodawari/ffd/lengths.hpp"

namespace kodawari::bind {

namespace {

using ffd::AxisBinding;

Vec3List to_control_points(const py::handle& obj) {
  Vec3List points = to_points(obj, "control_points");
  ffd::validate_control_points(points, "control_points");
  return points;
}

std::vector<Real> to_twist(const py::handle& obj, std::size_t count) {
  if (obj.is_none()) return {};
  return to_vector(obj, "twist", static_cast<py::ssize_t>(count));
}

std::optional<Vec3> to_up(const py::handle& obj) {
  if (obj.is_none()) return std::nullopt;
  return vec3(obj, "up");
}

template <typename Field>
py::array_t<float> coordinate_column(const AxisBinding& binding, Field field) {
  py::array_t<float> out(static_cast<py::ssize_t>(binding.count()));
  float* data = out.mutable_data();
  for (std::size_t i = 0; i < binding.count(); ++i) data[i] = field(i);
  return out;
}

py::tuple affine_to_python(const ffd::AffineCoordinates& affine) {
  py::array_t<float> rows({py::ssize_t(3), py::ssize_t(4)});
  float* data = rows.mutable_data();
  for (int k = 0; k < 3; ++k) {
    for (int j = 0; j < 4; ++j) data[4 * k + j] = affine.rows[k][j];
  }
  return py::make_tuple(rows, py::make_tuple(affine.holds[0], affine.holds[1], affine.holds[2]),
                        py::make_tuple(affine.worst[0], affine.worst[1], affine.worst[2]));
}

}  // namespace

void bind_ffd(py::module_& m) {
  py::class_<AxisBinding, std::shared_ptr<AxisBinding>>(
      m, "AxisBinding", "A mesh bound to a control axis: per vertex (t, u, v, w); see ffd_bind.")
      .def_property_readonly("count", &AxisBinding::count, "number of bound vertices N")
      .def_property_readonly("control_point_count", &AxisBinding::control_point_count)
      .def_property_readonly(
          "t", [](const AxisBinding& b) { return coordinate_column(b, [&](std::size_t i) { return b.parameter(i); }); },
          "float32 (N,) curve parameter of each vertex's closest curve point, in [0, 1]")
      .def_property_readonly(
          "u", [](const AxisBinding& b) { return coordinate_column(b, [&](std::size_t i) { return b.coordinates()[i].u; }); },
          "float32 (N,) offset along e2")
      .def_property_readonly(
          "v", [](const AxisBinding& b) { return coordinate_column(b, [&](std::size_t i) { return b.coordinates()[i].v; }); },
          "float32 (N,) offset along e3")
      .def_property_readonly(
          "w", [](const AxisBinding& b) { return coordinate_column(b, [&](std::size_t i) { return b.coordinates()[i].w; }); },
          "float32 (N,) offset along e1, non-zero only beyond the curve's ends")
      .def(
          "deform",
          [](const AxisBinding& b, const py::handle& control_points, const py::handle& out, const py::handle& twist,
             const py::handle& up, unsigned threads) {
            const Vec3List points = to_control_points(control_points);
            if (points.size() != static_cast<std::size_t>(b.control_point_count())) {
              throw py::value_error("control_points must have " + std::to_string(b.control_point_count()) +
                                    " points, as at bind time");
            }
            const std::vector<Real> twist_values = to_twist(twist, points.size());
            const std::optional<Vec3> up_hint = to_up(up);
            auto target = checked_output<float>(out, "out", static_cast<py::ssize_t>(b.count()), 3);
            if (threads > kMaxThreads) throw py::value_error("threads must be 0 (all cores) .. 1024");
            float* data = target.mutable_data();
            {
              // The core refuses a curve that would give non-finite positions before it writes
              // anything (std::invalid_argument -> ValueError): `out` may be a shape key's own
              // memory, and a second pass over it here would cost a read of 12 bytes per vertex.
              py::gil_scoped_release release;
              b.deform(points, twist_values, up_hint, data, threads);
            }
          },
          py::arg("control_points"), py::arg("out"), py::arg("twist") = py::none(), py::arg("up") = py::none(),
          py::arg("threads") = 0,
          "Write the mesh deformed by new control points into `out` (float32 (N, 3)); the GIL is released.")
      .def(
          "frame_table",
          [](const AxisBinding& b, const py::handle& control_points, const py::handle& out, const py::handle& twist,
             const py::handle& up) {
            const Vec3List points = to_control_points(control_points);
            const std::vector<Real> twist_values = to_twist(twist, points.size());
            const std::optional<Vec3> up_hint = to_up(up);
            auto target = checked_output<float>(out, "out", 8 * ffd::kTableSegments, 3);
            ffd::FrameTable table;
            b.frame_table(points, twist_values, up_hint, table);
            float* data = target.mutable_data();
            const std::size_t n = table.size();
            for (std::size_t i = 0; i < n; ++i) {
              const ffd::TableSegment& s = table[i];
              const ffd::Vec4f* fields[8] = {&s.origin, &s.d_origin, &s.e1, &s.d_e1, &s.e2, &s.d_e2, &s.e3, &s.d_e3};
              for (std::size_t f = 0; f < 8; ++f) {
                for (int k = 0; k < 3; ++k) data[3 * (f * n + i) + k] = (*fields[f])[k];
              }
            }
          },
          py::arg("control_points"), py::arg("out"), py::arg("twist") = py::none(), py::arg("up") = py::none(),
          "Write the frame table deform() uses into `out`, float32 (8 * 1024, 3): origin, its change across each "
          "segment, e1, its change, e2, its change, e3, its change; 1024 rows each.")
      .def(
          "packed_coordinates",
          [](const AxisBinding& b, double end_scale) {
            if (!(end_scale > 0) || !std::isfinite(end_scale)) throw py::value_error("end_scale must be > 0");
            py::array_t<float> out({static_cast<py::ssize_t>(b.count()), py::ssize_t(3)});
            float* data = out.mutable_data();
            {
              py::gil_scoped_release release;
              b.packed_coordinates(static_cast<float>(end_scale), data);
            }
            return out;
          },
          py::arg("end_scale"),
          "float32 (N, 3): (s, u, v) per vertex, s = segment + fraction, or beyond an end w * end_scale "
          "(head) / 1024 + w * end_scale (tail).")
      .def(
          "affine_coordinates",
          [](const AxisBinding& b, const py::handle& vertices, double end_scale, double tolerance) {
            if (!(end_scale > 0) || !std::isfinite(end_scale)) throw py::value_error("end_scale must be > 0");
            if (!(tolerance >= 0) || !std::isfinite(tolerance)) throw py::value_error("tolerance must be >= 0");
            const auto verts = checked_array<float>(vertices, "vertices", static_cast<py::ssize_t>(b.count()), 3);
            ffd::AffineCoordinates affine;
            {
              py::gil_scoped_release release;
              affine = b.affine_coordinates(verts.data(), b.count(), static_cast<float>(end_scale), tolerance);
            }
            return affine_to_python(affine);
          },
          py::arg("vertices"), py::arg("end_scale"), py::arg("tolerance"),
          "(rows float32 (3, 4), holds (3 bools), worst (3 floats)): which packed coordinates (s, u, v) "
          "are n . P + c of the bound rest positions `vertices` within `tolerance` body lengths "
          "(docs/algorithms.md §1.6); row k is (n, c).")
      .def("release_coordinates", &AxisBinding::release_coordinates,
           "Free the per-vertex coordinates (kept in a packed attribute instead); frame_table still works.")
      .def_property_readonly("released", &AxisBinding::released);

  m.def(
      "release_free_memory",
      []() {
#if defined(__GLIBC__)
        // A bind frees tens of bytes per vertex of scratch (rest positions, closest-point
        // search, packed copies); glibc keeps what fell below its mmap threshold in the heap,
        // where the process's resident memory still counts it (60 MB at 1 M vertices).
        return malloc_trim(0) != 0;
#else
        return false;
#endif
      },
      "Return the heap's free memory to the system (after a bind); True when some was returned.");

  m.def(
      "ffd_deform_packed",
      [](const py::handle& table, const py::handle& packed, double end_scale, const py::handle& out) {
        if (!(end_scale > 0) || !std::isfinite(end_scale)) throw py::value_error("end_scale must be > 0");
        const auto rows = checked_array<float>(table, "table", 8 * ffd::kTableSegments, 3);
        const auto coordinates = checked_array<float>(packed, "packed", -1, 3);
        const py::ssize_t n = coordinates.shape(0);
        auto target = checked_output<float>(out, "out", n, 3);
        no_overlap(target, "out", coordinates, "packed");
        ffd::FrameTable frame_table(ffd::kTableSegments);
        const float* data = rows.data();
        for (std::size_t i = 0; i < frame_table.size(); ++i) {
          ffd::TableSegment& s = frame_table[i];
          ffd::Vec4f* fields[8] = {&s.origin, &s.d_origin, &s.e1, &s.d_e1, &s.e2, &s.d_e2, &s.e3, &s.d_e3};
          for (std::size_t f = 0; f < 8; ++f) {
            const float* v = data + 3 * (f * frame_table.size() + i);
            *fields[f] = ffd::Vec4f(v[0], v[1], v[2], 0.0f);
          }
        }
        float* result = target.mutable_data();
        const float* source = coordinates.data();
        {
          py::gil_scoped_release release;
          ffd::deform_packed(frame_table, source, static_cast<std::size_t>(n), static_cast<float>(end_scale), result);
        }
      },
      py::arg("table"), py::arg("packed"), py::arg("end_scale"), py::arg("out"),
      "Deform packed (s, u, v) coordinates (float32 (N, 3)) by a frame table (float32 (8 * 1024, 3), "
      "AxisBinding.frame_table) into out (float32 (N, 3)): what the Fish Swim modifier computes.");

  m.def(
      "ffd_fill_affine_coordinates",
      [](const py::handle& rows, const py::sequence& holds, const py::handle& vertices, const py::handle& packed) {
        const auto row_array = checked_array<float>(rows, "rows", 3, 4);
        if (py::len(holds) != 3) throw py::value_error("holds must have 3 values (s, u, v)");
        const auto verts = checked_array<float>(vertices, "vertices", -1, 3);
        auto target = checked_output<float>(packed, "packed", verts.shape(0), 3);
        no_overlap(target, "packed", verts, "vertices");
        ffd::AffineCoordinates affine;
        for (int k = 0; k < 3; ++k) {
          affine.holds[k] = py::cast<bool>(holds[k]);
          for (int j = 0; j < 4; ++j) affine.rows[k][j] = row_array.data()[4 * k + j];
        }
        float* data = target.mutable_data();
        {
          py::gil_scoped_release release;
          ffd::fill_affine_coordinates(affine, verts.data(), static_cast<std::size_t>(verts.shape(0)), data);
        }
      },
      py::arg("rows"), py::arg("holds"), py::arg("vertices"), py::arg("packed"),
      "Write each packed coordinate k whose holds[k] is true as rows[k] . (P, 1) of the rest positions "
      "`vertices` (float32 (N, 3)) into column k of `packed` (float32 (N, 3)); what the Fish Swim "
      "modifier computes from Position instead of a stored attribute.");

  m.def(
      "ffd_bind",
      [](const py::handle& control_points, const py::handle& vertices, const py::handle& twist, const py::handle& up) {
        const Vec3List points = to_control_points(control_points);
        const std::vector<Real> twist_values = to_twist(twist, points.size());
        const std::optional<Vec3> up_hint = to_up(up);
        const auto verts = checked_array<float>(vertices, "vertices", -1, 3);
        if (verts.shape(0) == 0) throw py::value_error("vertices must not be empty");
        const float* data = verts.data();
        const std::size_t count = static_cast<std::size_t>(verts.shape(0));
        std::shared_ptr<AxisBinding> binding;
        {
          py::gil_scoped_release release;
          binding = std::make_shared<AxisBinding>(points, data, count, twist_values, up_hint);
        }
        for (const ffd::AxisCoordinate& c : binding->coordinates()) {
          const float values[4] = {c.fraction, c.u, c.v, c.w};
          require_finite_result(values, 4, "control_points: the curve is too close to degenerate to bind these "
                                           "vertices (non-finite coordinates); spread the points apart");
        }
        return binding;
      },
      py::arg("control_points"), py::arg("vertices"), py::arg("twist") = py::none(), py::arg("up") = py::none(),
      "Bind float32 (N, 3) vertices to the clamped cubic B-spline of float64 (n, 3) control points (n >= 4).");

  m.def(
      "ffd_frames",
      [](const py::handle& control_points, const py::handle& twist, const py::handle& up, int samples) {
        const Vec3List points = to_control_points(control_points);
        const std::vector<Real> twist_values = to_twist(twist, points.size());
        const std::optional<Vec3> up_hint = to_up(up);
        if (samples < 2 || samples > 100000) throw py::value_error("samples must be 2..100000");
        const ffd::FrameList frames = ffd::axis_frames(points, twist_values, up_hint, samples);
        py::array_t<double> out({static_cast<py::ssize_t>(samples), py::ssize_t(4), py::ssize_t(3)});
        double* data = out.mutable_data();
        for (std::size_t i = 0; i < frames.size(); ++i) {
          const ffd::Frame& f = frames[i];
          const Vec3* rows[4] = {&f.origin, &f.e1, &f.e2, &f.e3};
          for (int r = 0; r < 4; ++r) {
            for (int k = 0; k < 3; ++k) data[12 * i + 3 * r + k] = (*rows[r])[k];
          }
        }
        return out;
      },
      py::arg("control_points"), py::arg("twist") = py::none(), py::arg("up") = py::none(), py::arg("samples") = 64,
      "float64 (samples, 4, 3): origin M(t), e1, e2, e3 at t = linspace(0, 1, samples).");

  m.def(
      "curve_points",
      [](const py::handle& control_points, const py::handle& t) {
        const ffd::CubicBSpline curve(to_control_points(control_points));
        const auto params = checked_array<double>(t, "t", -1, 0);
        Vec3List points(static_cast<std::size_t>(params.shape(0)));
        for (std::size_t i = 0; i < points.size(); ++i) {
          const double value = params.data()[i];
          if (value < 0 || value > 1) throw py::value_error("t values must lie in [0, 1]");
          points[i] = curve.point(value);
        }
        return points_array(points);
      },
      py::arg("control_points"), py::arg("t"), "float64 (K, 3) curve points at parameters t in [0, 1].");

  m.def(
      "curve_length",
      [](const py::handle& control_points) { return ffd::curve_length(ffd::CubicBSpline(to_control_points(control_points))); },
      py::arg("control_points"), "Arc length of the clamped cubic B-spline.");

  m.def(
      "preserve_lengths",
      [](const py::handle& points, const py::handle& rest_lengths, long moved_index, std::optional<double> arc_length) {
        const Vec3List p = to_points(points, "points");
        const std::vector<Real> lengths = to_vector(rest_lengths, "rest_lengths");
        return points_array(ffd::preserve_lengths(p, lengths, moved_index, arc_length));
      },
      py::arg("points"), py::arg("rest_lengths"), py::arg("moved_index"), py::arg("arc_length") = py::none(),
      "The seed's distance-keeping pass: keep points[moved_index], restore every rest length toward both ends.\n"
      "With arc_length, scale all lengths by one factor until the curve's arc length equals it.");

  m.def(
      "preserve_lengths_from_head",
      [](const py::handle& points, const py::handle& rest_lengths, std::optional<double> arc_length) {
        const Vec3List p = to_points(points, "points");
        const std::vector<Real> lengths = to_vector(rest_lengths, "rest_lengths");
        return points_array(ffd::preserve_lengths_from_head(p, lengths, arc_length));
      },
      py::arg("points"), py::arg("rest_lengths"), py::arg("arc_length") = py::none(),
      "Pin point 0 and restore every rest length tailward (optionally matching arc_length, see preserve_lengths).");
}

}  // namespace kodawari::bind
