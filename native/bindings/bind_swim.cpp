// Python face of the swim kernels (native/include/kodawari/swim/): thin, every array checked.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <stdexcept>
#include <string>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/swim/body_wave.hpp"
#include "kodawari/swim/fin_motion.hpp"
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
      "Swimming speed (length units per second): BAINBRIDGE V = L(3f - 4)/4, STROUHAL U = f·A/St with "
      "A = 2·amplitude·L, NONE 0.");
}

}  // namespace kodawari::bind
