// Python face of the swim kernels (native/include/kodawari/swim/): thin, every array checked.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <memory>
#include <stdexcept>
#include <string>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/swim/body_wave.hpp"
#include "kodawari/swim/fin_finder.hpp"
#include "kodawari/swim/fin_motion.hpp"
#include "kodawari/swim/fin_part.hpp"
#include "kodawari/swim/fin_reach.hpp"
#include "kodawari/swim/speed.hpp"

namespace kodawari::bind {

namespace {

// A swim result from finite arguments is finite, else the arguments are out of the
// kernel's range (e.g. a negative envelope_power at the head).
py::array_t<double> finite_points(const Vec3List& points, const char* arguments) {
  for (const Vec3& p : points) {
    if (!p.allFinite()) throw py::value_error(std::string(arguments) + " give a non-finite result: bring them into range");
  }
  return points_array(points);
}

swim::FinMotion fin_motion_from(const std::string& name) {
  if (name == "FLAP") return swim::FinMotion::Flap;
  if (name == "UP_DOWN") return swim::FinMotion::UpDown;
  if (name == "TWIST") return swim::FinMotion::Twist;
  if (name == "UNDULATE") return swim::FinMotion::Undulate;
  throw py::value_error("motion must be one of FLAP, UP_DOWN, TWIST, UNDULATE, got " + name);
}

swim::SpeedMode speed_mode_from(const std::string& name) {
  if (name == "NONE") return swim::SpeedMode::None;
  if (name == "BAINBRIDGE") return swim::SpeedMode::Bainbridge;
  if (name == "STROUHAL") return swim::SpeedMode::Strouhal;
  throw py::value_error("mode must be one of NONE, BAINBRIDGE, STROUHAL, got " + name);
}

// Mesh edges: a C-contiguous int32 (E, 2) array (what Mesh.edges.foreach_get("vertices") gives).
py::array_t<std::int32_t> checked_edges(const py::handle& obj) {
  if (!py::isinstance<py::array>(obj)) throw py::value_error("edges must be a numpy array of int32");
  auto arr = py::reinterpret_borrow<py::array>(obj);
  if (!arr.dtype().is(py::dtype::of<std::int32_t>())) throw py::value_error("edges must be int32");
  if (!(arr.flags() & py::array::c_style)) throw py::value_error("edges must be C-contiguous");
  if (arr.ndim() != 2 || arr.shape(1) != 2) throw py::value_error("edges must have shape (E, 2)");
  return py::reinterpret_borrow<py::array_t<std::int32_t>>(arr);
}

}  // namespace

void bind_swim(py::module_& m) {
  m.def(
      "swim_body_axis",
      [](const py::handle& rest_points, const py::handle& bend_direction, double body_length, double phase,
         double wavelength, double amplitude, double amplitude_head, double envelope_start, double envelope_power,
         double phase_offset, bool preserve_length) {
        auto rest = checked_array<double>(rest_points, "rest_points", -1, 3);
        if (rest.shape(0) < 2) throw py::value_error("rest_points needs at least 2 points");
        const Vec3 bend = unit_vector(bend_direction, "bend_direction");
        for (auto [v, n] : {std::pair{body_length, "body_length"}, {phase, "phase"}, {wavelength, "wavelength"},
                            {amplitude, "amplitude"}, {amplitude_head, "amplitude_head"},
                            {envelope_start, "envelope_start"}, {envelope_power, "envelope_power"},
                            {phase_offset, "phase_offset"}}) {
          require_finite(v, n);
        }
        if (body_length <= 0) throw py::value_error("body_length must be positive");
        if (wavelength <= 0) throw py::value_error("wavelength must be positive");
        swim::BodyWave wave{wavelength, amplitude, amplitude_head, envelope_start, envelope_power, phase_offset,
                            preserve_length};
        Vec3List axis;
        try {
          axis = swim::body_axis(to_points(rest, "rest_points"), bend, body_length, wave, phase);
        } catch (const std::invalid_argument& e) {  // the core names its own terms: say which argument
          throw py::value_error(std::string("rest_points: ") + e.what());
        }
        return finite_points(axis, "amplitude, amplitude_head, envelope_start and envelope_power");
      },
      py::arg("rest_points"), py::arg("bend_direction"), py::arg("body_length"), py::arg("phase"),
      py::arg("wavelength") = 1.0, py::arg("amplitude") = 0.1, py::arg("amplitude_head") = 0.0,
      py::arg("envelope_start") = 0.0, py::arg("envelope_power") = 1.0, py::arg("phase_offset") = 0.0,
      py::arg("preserve_length") = true,
      "Body control axis (n, 3) for an accumulated phase: the rest axis displaced along bend_direction by "
      "the travelling wave, lengths kept from the head when preserve_length.");

  m.def(
      "swim_wave_envelope",
      [](double s, double amplitude, double amplitude_head, double envelope_start, double envelope_power) {
        for (auto [v, n] : {std::pair{s, "s"}, {amplitude, "amplitude"}, {amplitude_head, "amplitude_head"},
                            {envelope_start, "envelope_start"}, {envelope_power, "envelope_power"}}) {
          require_finite(v, n);
        }
        swim::BodyWave wave;
        wave.amplitude = amplitude;
        wave.amplitude_head = amplitude_head;
        wave.envelope_start = envelope_start;
        wave.envelope_power = envelope_power;
        const double peak = swim::wave_envelope(wave, s);
        if (!std::isfinite(peak)) throw py::value_error("envelope_power and s give a non-finite envelope");
        return peak;
      },
      py::arg("s"), py::arg("amplitude"), py::arg("amplitude_head"), py::arg("envelope_start"),
      py::arg("envelope_power"), "Peak amplitude (fraction of body length) at body fraction s.");

  m.def(
      "swim_fin_axis",
      [](const py::handle& rest_points, const py::handle& tangent, const py::handle& side, const py::handle& up,
         const std::string& motion, double amplitude, double phase, double feathering, double wavelength,
         int fixed_count, bool feather_on_power) {
        auto rest = checked_array<double>(rest_points, "rest_points", -1, 3);
        if (rest.shape(0) < 2) throw py::value_error("rest_points needs at least 2 points");
        swim::RootFrame frame{unit_vector(tangent, "tangent"), unit_vector(side, "side"), unit_vector(up, "up")};
        for (auto [v, n] : {std::pair{amplitude, "amplitude"}, {phase, "phase"}, {feathering, "feathering"},
                            {wavelength, "wavelength"}}) {
          require_finite(v, n);
        }
        if (wavelength <= 0) throw py::value_error("wavelength must be positive");
        swim::FinWave wave{fin_motion_from(motion), amplitude, feathering, feather_on_power, wavelength,
                           fixed_count};
        swim::FinPose pose;
        try {
          pose = swim::fin_axis(to_points(rest, "rest_points"), frame, wave, phase);
        } catch (const std::invalid_argument& e) {
          throw py::value_error(std::string("rest_points: ") + e.what());
        }
        require_finite_result(pose.twist.data(), pose.twist.size(), "amplitude and feathering give a non-finite twist");
        return py::make_tuple(finite_points(pose.points, "amplitude, feathering and fixed_count"), to_array(pose.twist));
      },
      py::arg("rest_points"), py::arg("tangent"), py::arg("side"), py::arg("up"), py::arg("motion"),
      py::arg("amplitude"), py::arg("phase"), py::arg("feathering") = 0.0, py::arg("wavelength") = 1.0,
      py::arg("fixed_count") = 3, py::arg("feather_on_power") = false,
      "Fin control axis for a phase: (points (m, 3), twist (m,)) in rest space; motion is FLAP, UP_DOWN, TWIST "
      "or UNDULATE.");

  m.def(
      "swim_flap_stroke_direction",
      [](const py::handle& fin_axis, const py::handle& tangent, const py::handle& side, const py::handle& up) {
        swim::RootFrame frame{unit_vector(tangent, "tangent"), unit_vector(side, "side"), unit_vector(up, "up")};
        return vec3_array(swim::flap_stroke_direction(unit_vector(fin_axis, "fin_axis"), frame));
      },
      py::arg("fin_axis"), py::arg("tangent"), py::arg("side"), py::arg("up"),
      "Unit direction a FLAP power stroke moves the fin tip in.");

  m.def(
      "swim_accumulate_phase",
      [](const py::handle& frequencies, double dt, double phase0) {
        const std::vector<double> values = to_vector(frequencies, "frequencies");
        require_finite(dt, "dt");
        require_finite(phase0, "phase0");
        const std::vector<double> phase = swim::accumulate_phase(values, dt, phase0);
        return to_array(phase);
      },
      py::arg("frequencies"), py::arg("dt"), py::arg("phase0") = 0.0,
      "Phases (radians) of a sampled frequency (Hz), accumulated by the trapezoid rule (φ += ω·dt).");

  m.def(
      "swim_speed",
      [](const std::string& mode, double body_length, double frequency, double amplitude, double strouhal) {
        for (auto [v, n] : {std::pair{body_length, "body_length"}, {frequency, "frequency"}, {amplitude, "amplitude"},
                            {strouhal, "strouhal"}}) {
          require_finite(v, n);
        }
        const double speed = swim::swim_speed(speed_mode_from(mode), body_length, frequency, amplitude, strouhal);
        if (!std::isfinite(speed)) throw py::value_error("strouhal must not be 0 (the speed is not finite)");
        return speed;
      },
      py::arg("mode"), py::arg("body_length"), py::arg("frequency"), py::arg("amplitude"), py::arg("strouhal"),
      "Swimming speed (length units per second): BAINBRIDGE V = L(3f - 4)/4 where it gives Strouhal 0.2-0.4 "
      "(else the STROUHAL speed), "
      "STROUHAL U = f·A/St with A = 2·amplitude·L, NONE 0; with amplitude 0 (a fin swimmer) 0.5·L·f.");

  m.def("swim_bainbridge_applies", &swim::bainbridge_applies, py::arg("frequency"),
        "Whether Bainbridge's V = L(3f - 4)/4 was fitted at this tail-beat frequency (about 5 Hz and up).");
  m.def(
      "swim_fin_axis_coordinates",
      [](const py::handle& axis_points, const py::handle& up, const py::handle& vertices, const py::handle& out,
         long begin, long end) {
        auto axis = checked_array<double>(axis_points, "axis_points", -1, 3);
        if (axis.shape(0) < 2) throw py::value_error("axis_points needs at least 2 points");
        const Vec3 up_direction = unit_vector(up, "up");
        auto verts = checked_array<float>(vertices, "vertices", -1, 3);
        auto target = checked_output<float>(out, "out", verts.shape(0), 3);
        if (begin < 0 || end < begin || end > verts.shape(0)) throw py::value_error("begin/end out of range");
        const Vec3List points = to_points(axis);
        const float* v = verts.data();
        float* o = target.mutable_data();
        no_overlap(target, "out", verts, "vertices");
        py::gil_scoped_release release;
        try {
          swim::fin_axis_coordinates(points, up_direction, v, static_cast<std::size_t>(begin),
                                     static_cast<std::size_t>(end), o);
        } catch (const std::invalid_argument& e) {  // the core names its own terms: say which argument
          throw std::invalid_argument(std::string("axis_points: ") + e.what());
        }
      },
      py::arg("axis_points"), py::arg("up"), py::arg("vertices"), py::arg("out"), py::arg("begin"), py::arg("end"),
      "Fin finder, stage 1 (call in chunks for progress): for vertices[begin:end] write (s, side, up) into out: "
      "arc fraction of the nearest axis point and the offset across the axis, in axis lengths.");

  m.def(
      "swim_find_fins",
      [](const py::handle& coordinates, const py::handle& edges, int slices, int sectors, double outside,
         double margin, std::size_t min_vertices) {
        auto coords = checked_array<float>(coordinates, "coordinates", -1, 3);
        auto e = checked_edges(edges);
        if (slices < 1 || slices > 4096 || sectors < 8 || sectors > 4096) {
          throw py::value_error("slices must be 1..4096 and sectors 8..4096");
        }
        for (auto [v, n] : {std::pair{outside, "outside"}, {margin, "margin"}}) require_finite(v, n);
        swim::FinFinderOptions options;
        options.slices = slices;
        options.sectors = sectors;
        options.outside = outside;
        options.margin = margin;
        options.min_vertices = min_vertices;
        const float* c = coords.data();
        const std::int32_t* ed = e.data();
        const std::size_t n = static_cast<std::size_t>(coords.shape(0));
        const std::size_t ne = static_cast<std::size_t>(e.shape(0));
        std::vector<std::int8_t> kinds;
        {
          py::gil_scoped_release release;
          kinds = swim::find_fins(c, n, ed, ne, options);  // std::invalid_argument -> ValueError
        }
        py::array_t<std::int8_t> out(static_cast<py::ssize_t>(n));
        std::copy(kinds.begin(), kinds.end(), out.mutable_data());
        return out;
      },
      py::arg("coordinates"), py::arg("edges"), py::arg("slices") = 48, py::arg("sectors") = 32,
      py::arg("outside") = 1.2, py::arg("margin") = 0.004, py::arg("min_vertices") = 8,
      "Fin finder, stage 2: int8 (N,) fin kind per vertex from stage 1's coordinates and int32 (E, 2) edges: "
      "0 body, 1 caudal, 2 dorsal, 3 anal, 4 pelvic, 5 pectoral.");
  m.def(
      "swim_nearest_distances",
      [](const py::handle& points, const py::handle& cloud) {
        auto p = checked_array<float>(points, "points", -1, 3);
        auto c = checked_array<float>(cloud, "cloud", -1, 3);
        if (c.shape(0) == 0) throw py::value_error("cloud is empty: there is no nearest point");
        const float* pd = p.data();
        const float* cd = c.data();
        const std::size_t n = static_cast<std::size_t>(p.shape(0)), m = static_cast<std::size_t>(c.shape(0));
        std::vector<Real> d;
        {
          py::gil_scoped_release release;
          d = swim::nearest_distances(pd, n, cd, m);
        }
        py::array_t<double> out(static_cast<py::ssize_t>(n));
        std::copy(d.begin(), d.end(), out.mutable_data());
        return out;
      },
      py::arg("points"), py::arg("cloud"),
      "float64 (N,): each float32 point's distance to the nearest point of the float32 (M, 3) cloud (M >= 1).");
  m.def(
      "swim_fin_reach",
      [](const py::handle& vertices, const py::handle& edges, const py::handle& in_fin, double seed_radius,
         const py::handle& squash) {
        auto v = checked_array<float>(vertices, "vertices", -1, 3);
        auto e = checked_edges(edges);
        require_finite(seed_radius, "seed_radius");
        if (!py::isinstance<py::array>(in_fin)) throw py::value_error("in_fin must be a numpy array of bool");
        auto mask = py::reinterpret_borrow<py::array>(in_fin);
        if (!mask.dtype().is(py::dtype::of<bool>()) || mask.ndim() != 1 || mask.shape(0) != v.shape(0) ||
            !(mask.flags() & py::array::c_style)) {
          throw py::value_error("in_fin must be a contiguous bool array with one value per vertex");
        }
        const float* vd = v.data();
        const std::int32_t* ed = e.data();
        const auto* md = static_cast<const std::uint8_t*>(mask.data());
        const std::size_t n = static_cast<std::size_t>(v.shape(0)), ne = static_cast<std::size_t>(e.shape(0));
        std::vector<float> directions;
        if (!squash.is_none()) {
          auto q = checked_array<float>(squash, "squash", v.shape(0), 9);
          directions.assign(q.data(), q.data() + 9 * n);
        }
        std::vector<Real> reach;
        std::vector<std::int64_t> source;
        {
          py::gil_scoped_release release;
          reach = swim::fin_reach(vd, n, ed, ne, md, seed_radius, &source, 0,
                                  directions.empty() ? nullptr : directions.data(), swim::kSwingReachSlope);
        }
        py::array_t<double> out(static_cast<py::ssize_t>(n));
        std::copy(reach.begin(), reach.end(), out.mutable_data());
        py::array_t<std::int64_t> from(static_cast<py::ssize_t>(n));
        std::copy(source.begin(), source.end(), from.mutable_data());
        return py::make_tuple(out, from);
      },
      py::arg("vertices"), py::arg("edges"), py::arg("in_fin"), py::arg("seed_radius"), py::arg("squash") = py::none(),
      "(reach float64 (N,), source int64 (N,)): for fin vertices, the path length across the fin from where it "
      "meets the body (0 elsewhere), and the vertex at the root that path starts from. squash: float32 (N, 9), "
      "per vertex a row-major 3x3 projector onto the directions its part's motion moves it in (zero rows: "
      "none): an edge's extent in them counts 0.6 times, so the reach grows slowly along the motion.");
  py::class_<swim::FinPartBinding, std::shared_ptr<swim::FinPartBinding>>(
      m, "FinPart", "One fin part bound for motion: every vertex swings about its own root point, faded in by weight "
      "(fade > 0: weight × smoothstep(reach / fade), the swing bent along the fin so no line stretches).")
      .def(py::init([](const py::handle& points, const py::handle& reach, const py::handle& weight,
                       const py::handle& root, const py::handle& outward, const py::handle& tangent,
                       const py::handle& side, const py::handle& up, double height, double base_length,
                       double base_front, double fade) {
             auto p = checked_array<float>(points, "points", -1, 3);
             const py::ssize_t m = p.shape(0);
             auto r = checked_array<double>(reach, "reach", m, 0);
             auto w = checked_array<double>(weight, "weight", m, 0);
             for (auto [v, n] : {std::pair{height, "height"}, {base_length, "base_length"}, {base_front, "base_front"}, {fade, "fade"}}) {
               require_finite(v, n);
             }
             Vec3List pts(static_cast<std::size_t>(m));
             for (py::ssize_t i = 0; i < m; ++i) pts[i] = Vec3(p.data()[3 * i], p.data()[3 * i + 1], p.data()[3 * i + 2]);
             auto a = checked_array<double>(root, "root", 3, 0);
             swim::FinPartRest rest;
             rest.root = Vec3(a.data()[0], a.data()[1], a.data()[2]);
             rest.outward = unit_vector(outward, "outward");
             rest.frame = {unit_vector(tangent, "tangent"), unit_vector(side, "side"), unit_vector(up, "up")};
             rest.height = height;
             rest.base_length = base_length;
             rest.base_front = base_front;
             return std::make_shared<swim::FinPartBinding>(
                 pts, std::vector<Real>(r.data(), r.data() + m), std::vector<Real>(w.data(), w.data() + m), rest,
                 fade);
           }),
           py::arg("points"), py::arg("reach"), py::arg("weight"), py::arg("root"), py::arg("outward"),
           py::arg("tangent"), py::arg("side"), py::arg("up"), py::arg("height"), py::arg("base_length"),
           py::arg("base_front"), py::arg("fade") = 0.0)
      .def_property_readonly("count", &swim::FinPartBinding::count)
      .def_property_readonly("max_roll", &swim::FinPartBinding::max_roll)
      .def_property_readonly("max_feather", &swim::FinPartBinding::max_feather)
      .def_property_readonly("max_undulation", &swim::FinPartBinding::max_undulation)
      .def(
          "swing_direction",
          [](const swim::FinPartBinding& b, const std::string& motion) {
            const Vec3 d = b.swing_direction(fin_motion_from(motion));
            py::array_t<double> out(3);
            std::copy(d.data(), d.data() + 3, out.mutable_data());
            return out;
          },
          py::arg("motion"),
          "float64 (3,): the unit direction the motion's swing moves this part's lines in (hinge x outward; zero "
          "for TWIST and UNDULATE).")

      .def(
          "displace",
          [](const swim::FinPartBinding& b, const std::string& motion, double amplitude, double phase,
             double feathering, double wavelength, bool feather_on_power, const py::handle& probes_rest,
             const py::handle& probes_now, const py::handle& out) {
            for (auto [v, n] : {std::pair{amplitude, "amplitude"}, {phase, "phase"}, {feathering, "feathering"},
                                {wavelength, "wavelength"}}) {
              require_finite(v, n);
            }
            if (wavelength <= 0) throw py::value_error("wavelength must be positive");
            auto pr = checked_array<float>(probes_rest, "probes_rest", 4, 3);
            auto pn = checked_array<float>(probes_now, "probes_now", 4, 3);
            auto target = checked_output<float>(out, "out", static_cast<py::ssize_t>(b.count()), 3);
            Vec3List before(4), now(4);
            for (int i = 0; i < 4; ++i) {
              before[i] = Vec3(pr.data()[3 * i], pr.data()[3 * i + 1], pr.data()[3 * i + 2]);
              now[i] = Vec3(pn.data()[3 * i], pn.data()[3 * i + 1], pn.data()[3 * i + 2]);
            }
            swim::FinWave wave{fin_motion_from(motion), amplitude, feathering, feather_on_power, wavelength, 3};
            float* o = target.mutable_data();
            {
              py::gil_scoped_release release;
              b.displace(wave, phase, swim::probe_rotation(before, now), o);
            }
            require_finite_result(o, 3 * b.count(),
                                  "out: probes_rest / probes_now give no finite displacement (degenerate probes)");
          },
          py::arg("motion"), py::arg("amplitude"), py::arg("phase"), py::arg("feathering"), py::arg("wavelength"),
          py::arg("feather_on_power"), py::arg("probes_rest"), py::arg("probes_now"), py::arg("out"),
          "Write the part's displacements (float32 (M, 3)) for a phase, turned with the body's rotation at the "
          "root (from 4 probe points, root + 3 arms, at rest and now).");
}

}  // namespace kodawari::bind
