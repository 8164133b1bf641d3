// Quadruped gaits: the gait table, the whole-bake planner + CCD IK, forward
// kinematics for the report. Thin: checks arrays, converts, releases the GIL.
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cmath>
#include <string>
#include <vector>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/gait/ccd_ik.hpp"
#include "kodawari/gait/gait_table.hpp"
#include "kodawari/gait/planner.hpp"

namespace kodawari::bind {

namespace {

using namespace kodawari::gait;
constexpr int kColumns = 12;
const char* kGaitColumns[kColumns] = {"duty_factor", "phase_fore_hind", "phase_left_right", "swing_time",
                                      "swing_height", "swing_peak", "bob", "bobs_per_cycle", "speed_max",
                                      "froude_max", "use_in_auto", "duty_factor_top"};

GaitTable table_from(const py::handle& table) {
  const py::dict d = dict_arg(table, "table");
  GaitTable t;
  auto gaits = checked_array<double>(item(d, "gaits", "table"), "table['gaits']", kGaitCount, kColumns);
  for (int g = 0; g < kGaitCount; ++g) {
    const double* r = gaits.data() + g * kColumns;
    GaitParams& p = t.gaits[g];
    p.duty_factor = r[0];
    p.phase_fore_hind = r[1];
    p.phase_left_right = r[2];
    p.swing_time = r[3];
    p.swing_height = r[4];
    p.swing_peak = r[5];
    p.bob = r[6];
    p.bobs_per_cycle = r[7];
    p.speed_max = r[8];
    p.froude_max = r[9];
    p.use_in_auto = r[10] != 0;
    p.duty_factor_top = r[11];
  }
  t.use_froude = bool_item(d, "use_froude", "table");
  t.hysteresis = number_item(d, "hysteresis", "table");
  t.reach = number_item(d, "reach", "table");
  return t;
}

py::dict table_to(const GaitTable& t) {
  py::array_t<double> gaits({kGaitCount, kColumns});
  for (int g = 0; g < kGaitCount; ++g) {
    const GaitParams& p = t.gaits[g];
    const double row[kColumns] = {p.duty_factor, p.phase_fore_hind, p.phase_left_right, p.swing_time,
                                  p.swing_height, p.swing_peak, p.bob, p.bobs_per_cycle, p.speed_max,
                                  p.froude_max, p.use_in_auto ? 1.0 : 0.0, p.duty_factor_top};
    std::copy(row, row + kColumns, gaits.mutable_data() + g * kColumns);
  }
  py::dict d;
  d["gaits"] = gaits;
  d["use_froude"] = t.use_froude;
  d["hysteresis"] = t.hysteresis;
  d["reach"] = t.reach;
  return d;
}

Rig rig_from(const py::handle& rig_arg) {
  const py::dict d = dict_arg(rig_arg, "rig");
  Rig rig;
  rig.forward = vec3(item(d, "forward", "rig"), "rig['forward']");
  rig.body_head = vec3(item(d, "body_head", "rig"), "rig['body_head']");
  auto rest = checked_array<double>(item(d, "body_rest", "rig"), "rig['body_rest']", 3, 3);
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rig.body_rest(r, c) = rest.data()[r * 3 + c];
  const py::sequence legs = sequence_item(d, "legs", "rig");
  if (legs.size() != kLegCount) throw py::value_error("rig['legs'] must list 4 legs (LF, RF, LH, RH)");
  for (int leg = 0; leg < kLegCount; ++leg) {
    const std::string where = "rig['legs'][" + std::to_string(leg) + "]";
    const py::dict l = dict_arg(legs[leg], where);
    LegRig& out = rig.legs[leg];
    out.heads = to_points(item(l, "heads", where), where + "['heads']");
    const auto n = static_cast<py::ssize_t>(out.heads.size());
    out.tail = vec3(item(l, "tail", where), where + "['tail']");
    out.limit_min = to_vector(item(l, "limit_min", where), where + "['limit_min']", n);
    out.limit_max = to_vector(item(l, "limit_max", where), where + "['limit_max']", n);
    out.stiffness = to_vector(item(l, "stiffness", where), where + "['stiffness']", n);
  }
  const std::string why = validate_rig(rig);
  if (!why.empty()) throw py::value_error(why);
  return rig;
}

}  // namespace

void bind_gait(py::module_& m) {
  py::list columns;
  for (const char* c : kGaitColumns) columns.append(c);
  m.attr("GAIT_COLUMNS") = columns;
  py::tuple gait_names(kGaitCount), leg_names(kLegCount);
  for (int g = 0; g < kGaitCount; ++g) gait_names[g] = kGaitNames[g];
  for (int leg = 0; leg < kLegCount; ++leg) leg_names[leg] = kLegNames[leg];
  m.attr("GAIT_NAMES") = gait_names;
  m.attr("LEG_NAMES") = leg_names;
  m.attr("GAIT_HORSE_LEG_LENGTH") = kHorseLegLength;

  m.def("gait_horse_table", [](double leg_length) {
        const GaitTable t = horse_gait_table();
        require_finite(leg_length, "leg_length");
        return table_to(leg_length > 0 ? scale_table(t, leg_length) : t);
      }, py::arg("leg_length") = 0.0,
      "The horse defaults: {'gaits': (5, 12) float64 in GAIT_COLUMNS order, 'use_froude', 'hysteresis', 'reach'};"
      " with leg_length > 0 (m, hip height), scaled to that animal by dynamic similarity (Froude).");

  m.def("gait_duty_factor", [](const py::dict& table, int gait, double speed, double leg_length) {
        if (gait < 0 || gait >= kGaitCount) throw py::value_error("gait must be 0..4");
        return duty_at(table_from(table), static_cast<Gait>(gait), require_finite(speed, "speed"),
                       require_finite(leg_length, "leg_length"));
      }, py::arg("table"), py::arg("gait"), py::arg("speed"), py::arg("leg_length"),
      "The duty factor a gait uses at a speed (falls with speed where duty_factor_top says so).");

  m.def("gait_check_speeds", [](const py::dict& table, const py::handle& speed, const py::handle& mode,
                                double leg_length) {
        const GaitTable t = table_from(table);
        auto s = checked_array<double>(speed, "speed", -1, 0);
        const py::ssize_t frames = s.shape(0);
        auto m = checked_array<double>(mode, "gait_mode", frames, 0);
        std::vector<int> modes(frames);
        for (py::ssize_t f = 0; f < frames; ++f) modes[f] = static_cast<int>(m.data()[f]);
        const SpeedProblem p = check_speeds(t, s.data(), modes.data(), static_cast<int>(frames),
                                            require_finite(leg_length, "leg_length"));
        return py::make_tuple(p.frame, p.top);
      }, py::arg("table"), py::arg("speed"), py::arg("gait_mode"), py::arg("leg_length"),
      "(frame index, top speed) of the first frame faster than its gait mode allows, or (-1, 0).");

  m.def("gait_validate_table", [](const py::dict& table) { return validate_table(table_from(table)); },
        py::arg("table"), "Empty string when the table is usable, else what is wrong.");

  m.def("gait_validate_rig", [](const py::dict& rig) {
        try {
          rig_from(rig);
        } catch (const py::value_error& e) {
          return std::string(e.what());
        }
        return std::string();
      }, py::arg("rig"), "Empty string when the rig can be solved, else what is wrong.");

  m.def("gait_leg_phases", [](const py::dict& table, int gait) {
        if (gait < 0 || gait >= kGaitCount) throw py::value_error("gait must be 0..4");
        const GaitTable t = table_from(table);
        py::array_t<double> out(kLegCount);
        for (int leg = 0; leg < kLegCount; ++leg) out.mutable_data()[leg] = leg_phase(t.gaits[gait], static_cast<Gait>(gait), leg);
        return out;
      }, py::arg("table"), py::arg("gait"), "Lift-off phase of LF, RF, LH, RH relative to LH for one gait.");

  m.def("gait_seed_swing_distance", [](double speed_new, double speed_old, double swing_time, double duty_factor,
                                       double since_change, double added_time) {
        for (auto [v, n] : {std::pair{speed_new, "speed_new"}, {speed_old, "speed_old"}, {swing_time, "swing_time"},
                            {duty_factor, "duty_factor"}, {since_change, "since_change"}, {added_time, "added_time"}}) {
          require_finite(v, n);
        }
        if (!(duty_factor < 1)) throw py::value_error("duty_factor must be < 1");
        const double s = seed_swing_distance(speed_new, speed_old, swing_time, duty_factor, since_change, added_time);
        if (!std::isfinite(s)) throw py::value_error("duty_factor is too close to 1: the swing distance is not finite");
        return s;
      }, py::arg("speed_new"), py::arg("speed_old"),
        py::arg("swing_time"), py::arg("duty_factor"), py::arg("since_change"), py::arg("added_time"),
        "Seed eq. 3.6: S = V'P/(1-a) + (V'-V)C + V't.");

  m.def("gait_table_speed_max", [](const py::dict& table, int gait, double leg_length) {
        return table_speed_max(table_from(table), gait, require_finite(leg_length, "leg_length"));
      }, py::arg("table"), py::arg("gait"), py::arg("leg_length"),
      "Fastest speed the table covers: AUTO (gait=-1) or one gait.");

  m.def("gait_select", [](const py::dict& table, double speed, int current, double leg_length) {
        return static_cast<int>(select_gait(table_from(table), require_finite(speed, "speed"), current,
                                            require_finite(leg_length, "leg_length")));
      }, py::arg("table"), py::arg("speed"), py::arg("current"), py::arg("leg_length"));

  m.def("gait_ccd_solve", [](const py::dict& chain, const py::handle& target, const py::handle& angles,
                             int iterations, double tolerance) {
        LegChain c;
        auto lengths = checked_array<double>(item(chain, "lengths", "chain"), "chain['lengths']", -1, 0);
        const py::ssize_t n = lengths.shape(0);
        if (n < 2 || n > 6) throw py::value_error("a chain needs 2 to 6 bones");
        auto dirs = checked_array<double>(item(chain, "rest_direction", "chain"), "chain['rest_direction']", n, 0);
        auto lo = checked_array<double>(item(chain, "limit_min", "chain"), "chain['limit_min']", n, 0);
        auto hi = checked_array<double>(item(chain, "limit_max", "chain"), "chain['limit_max']", n, 0);
        auto st = checked_array<double>(item(chain, "stiffness", "chain"), "chain['stiffness']", n, 0);
        auto t = checked_array<double>(target, "target", 2, 0);
        auto a = checked_array<double>(angles, "angles", n, 0);
        if (iterations < 0 || iterations > 100000) throw py::value_error("iterations must be 0..100000");
        require_finite(tolerance, "tolerance");
        c.lengths.assign(lengths.data(), lengths.data() + n);
        c.rest_direction.assign(dirs.data(), dirs.data() + n);
        c.limit_min.assign(lo.data(), lo.data() + n);
        c.limit_max.assign(hi.data(), hi.data() + n);
        c.stiffness.assign(st.data(), st.data() + n);
        for (py::ssize_t k = 0; k < n; ++k) {
          if (!(c.lengths[k] > 0)) throw py::value_error("chain['lengths'] must be positive");
          if (!(c.limit_min[k] <= c.limit_max[k])) throw py::value_error("limit_min must be <= limit_max");
        }
        py::array_t<double> out(n);
        std::copy(a.data(), a.data() + n, out.mutable_data());
        const CcdResult r = solve_ccd(c, Vec2(t.data()[0], t.data()[1]), iterations, tolerance, out.mutable_data());
        require_finite_result(out.data(), static_cast<std::size_t>(n), "chain: the solve gave non-finite angles");
        return py::make_tuple(out, r.error, r.iterations);
      }, py::arg("chain"), py::arg("target"), py::arg("angles"), py::arg("iterations"), py::arg("tolerance"),
      "One CCD solve of a planar chain (root at 0, 0); returns (angles, error, iterations).");

  m.def("gait_bake", [](const py::dict& rig_d, const py::dict& table_d, const py::handle& target_speed,
                        const py::handle& gait_mode, double fps, double acceleration, int ccd_iterations,
                        const py::object& path, const py::object& ground) {
        BakeInput in;
        in.rig = rig_from(rig_d);
        in.table = table_from(table_d);
        const std::string why = validate_table(in.table);
        if (!why.empty()) throw py::value_error(why);
        auto speed = checked_array<double>(target_speed, "target_speed", -1, 0);
        const py::ssize_t frames = speed.shape(0);
        auto mode = checked_array<double>(gait_mode, "gait_mode", frames, 0);
        for (py::ssize_t f = 0; f < frames; ++f) {
          if (speed.data()[f] < 0) throw py::value_error("target_speed must be >= 0");
          const double g = mode.data()[f];
          if (g != std::floor(g) || g < -1 || g >= kGaitCount) throw py::value_error("gait_mode must hold integers -1..4");
        }
        if (!(fps > 0 && fps <= 1000)) throw py::value_error("fps must be in (0, 1000]");
        if (!(acceleration > 0)) throw py::value_error("acceleration must be > 0");
        require_finite(acceleration, "acceleration");
        if (ccd_iterations < 1 || ccd_iterations > 1000) throw py::value_error("ccd_iterations must be 1..1000");
        in.target_speed.assign(speed.data(), speed.data() + frames);
        for (py::ssize_t f = 0; f < frames; ++f) in.gait_mode.push_back(static_cast<int>(mode.data()[f]));
        // The table's speed range (the add-on's rule, check_speeds): past it no gait fits and
        // the legs cannot follow the body (a 10 km/s bake missed its feet by 55 m).
        double leg_length = 0;  // hip height above the feet, as the add-on measures it
        for (int leg : {kLH, kRH}) leg_length = std::max(leg_length, in.rig.legs[leg].heads[0].z() - in.rig.legs[leg].tail.z());
        const SpeedProblem too_fast = check_speeds(in.table, in.target_speed.data(), in.gait_mode.data(),
                                                   static_cast<int>(frames), leg_length);
        if (too_fast.frame >= 0) {
          throw py::value_error("target_speed[" + std::to_string(too_fast.frame) + "] = " +
                                std::to_string(in.target_speed[too_fast.frame]) + " is past the top speed " +
                                std::to_string(too_fast.top) + " of the gait table");
        }
        in.fps = fps;
        in.acceleration = acceleration;
        in.ccd_iterations = ccd_iterations;
        if (!path.is_none()) {
          in.path = to_points(path, "path");
          if (in.path.size() < 2) throw py::value_error("path needs at least 2 points");
        }
        if (!ground.is_none()) {
          const py::dict g = dict_arg(ground, "ground");
          auto h = checked_array<double>(item(g, "heights", "ground"), "ground['heights']", -1, 0);
          in.ground.nx = int_item(g, "nx", "ground");
          in.ground.ny = int_item(g, "ny", "ground");
          if (in.ground.nx < 2 || in.ground.ny < 2 || h.shape(0) != static_cast<py::ssize_t>(in.ground.nx) * in.ground.ny) {
            throw py::value_error("ground['heights'] must hold nx * ny values (nx, ny >= 2)");
          }
          in.ground.x0 = number_item(g, "x0", "ground");
          in.ground.y0 = number_item(g, "y0", "ground");
          in.ground.cell = number_item(g, "cell", "ground");
          if (!(in.ground.cell > 0)) throw py::value_error("ground['cell'] must be > 0");
          in.ground.heights.assign(h.data(), h.data() + h.shape(0));
        }
        BakeOutput out;
        {
          py::gil_scoped_release release;
          out = bake_gait(in);
        }
        for (const std::vector<Real>* v : {&out.angles, &out.body_location, &out.body_rotation, &out.feet, &out.roots,
                                           &out.headings, &out.ik_error}) {
          require_finite_result(v->data(), v->size(),
                                "the bake gave non-finite results: check path (repeated points), ground and target_speed");
        }
        const py::ssize_t F = out.frames, B = out.bones;
        py::dict d;
        d["angles"] = to_array(out.angles, {F, B});
        d["body_location"] = to_array(out.body_location, {F, 3});
        d["body_rotation"] = to_array(out.body_rotation, {F, 4});
        d["contacts"] = to_array(out.contacts, {F, 4});
        d["feet_planned"] = to_array(out.feet_planned, {F, 4, 3});
        d["feet"] = to_array(out.feet, {F, 4, 3});
        d["roots"] = to_array(out.roots, {F, 4, 3});
        d["headings"] = to_array(out.headings, {F, 3});
        d["gait"] = to_array(out.gait, {F});
        d["speed"] = to_array(out.speed, {F});
        d["ik_error"] = to_array(out.ik_error, {F, 4});
        d["reach"] = to_array(out.reach, {4});
        return d;
      }, py::arg("rig"), py::arg("table"), py::arg("target_speed"), py::arg("gait_mode"), py::arg("fps"),
      py::arg("acceleration"), py::arg("ccd_iterations"), py::arg("path") = py::none(), py::arg("ground") = py::none(),
      "Plans and solves a whole bake in one call; returns a dict of arrays (legs LF, RF, LH, RH).");

  m.def("gait_forward_kinematics", [](const py::dict& rig_d, const py::handle& angles, const py::handle& loc,
                                      const py::handle& rot) {
        const Rig rig = rig_from(rig_d);
        int bones = 0;
        for (const LegRig& l : rig.legs) bones += static_cast<int>(l.heads.size());
        auto a = checked_array<double>(angles, "angles", -1, bones);
        const py::ssize_t F = a.shape(0);
        auto l = checked_array<double>(loc, "body_location", F, 3);
        auto r = checked_array<double>(rot, "body_rotation", F, 4);
        py::array_t<double> feet({F, py::ssize_t(4), py::ssize_t(3)}), roots({F, py::ssize_t(4), py::ssize_t(3)});
        {
          py::gil_scoped_release release;
          forward_kinematics(rig, static_cast<int>(F), a.data(), l.data(), r.data(), feet.mutable_data(), roots.mutable_data());
        }
        return py::make_tuple(feet, roots);
      }, py::arg("rig"), py::arg("angles"), py::arg("body_location"), py::arg("body_rotation"),
      "Feet and leg roots (F, 4, 3) of baked channels.");
}

}  // namespace kodawari::bind
