// kodawari_native: view weights and the rod system (one crossing per frame for all rods).
#include <pybind11/numpy.h>
#include <pybind11/pybind11.h>
#include <pybind11/stl.h>

#include <cstdint>
#include <optional>
#include <stdexcept>

#include "arrays.hpp"
#include "bind.hpp"
#include "kodawari/rod/rod_step_ahead.hpp"
#include "kodawari/rod/rod_system.hpp"
#include "kodawari/rod/view_weights.hpp"

namespace kodawari::bind {

namespace {

using namespace kodawari::rod;

// One thread at a time per system: step/reset/store_frame/recall_frame release the GIL.
ExclusiveUse exclusive(const RodSystem& system) { return ExclusiveUse(&system, "RodSystem"); }

// Rod bones' rows of a frame's output are finite, else the solve diverged.
bool rod_rows_finite(const RodSystem& system, const float* rotations) {
  for (std::size_t r = 0; r < system.rod_count(); ++r) {
    for (int b : system.rod(r).bones) {
      for (int c = 0; c < 4; ++c) {
        if (!std::isfinite(rotations[4 * static_cast<std::size_t>(b) + c])) return false;
      }
    }
  }
  return true;
}

// The frame inputs shared by reset() and step(); validates every array.
FrameInput frame_input(const RodSystem& system, const py::handle& bone_matrices, const py::handle& armature_matrix,
                       const py::handle& camera, const py::handle& gravity, double time, double frame_dt,
                       py::array_t<float>& matrices_keep) {
  const auto rows = static_cast<py::ssize_t>(system.bone_count());
  matrices_keep = checked_array<float>(bone_matrices, "bone_matrices", rows, 16);
  auto arm = checked_array<double>(armature_matrix, "armature_matrix", 4, 4);
  FrameInput in;
  in.bone_matrices = matrices_keep.data();
  in.bone_count = system.bone_count();
  for (int r = 0; r < 4; ++r) {
    for (int c = 0; c < 4; ++c) in.armature_matrix(r, c) = arm.data()[4 * r + c];
  }
  if (std::abs(in.armature_matrix.block<3, 3>(0, 0).determinant()) < 1e-12) {
    throw py::value_error("armature_matrix is singular");
  }
  for (int r = 0; r < 3; ++r) {
    if (in.armature_matrix.block<3, 1>(0, r).norm() > 1e6) throw py::value_error("armature_matrix scale is out of range (> 1e6)");
  }
  in.has_camera = !camera.is_none();
  if (in.has_camera) in.camera = vec3(camera, "camera");
  in.gravity = vec3(gravity, "gravity");
  require_finite(time, "time");
  if (!std::isfinite(frame_dt) || frame_dt < 0 || frame_dt > 1e3) throw py::value_error("frame_dt must be in [0, 1000] seconds");
  in.time = time;
  in.frame_dt = frame_dt;
  return in;
}

std::size_t add_rod(RodSystem& system, int parent_bone, int reference_bone, const py::handle& bones,
                    const py::handle& offsets, const py::handle& rest_rotations, double stiffness, double damping,
                    double gravity, int substeps, int iterations, double radius, const py::handle& wind,
                    const py::handle& key_conditions, const py::handle& key_directions,
                    const py::handle& key_rotations, const py::handle& key_speeds, const py::handle& key_influences,
                    const py::handle& key_shapes, bool momentum_control) {
  auto b = checked_array<std::int32_t>(bones, "bones", -1, 0);
  const py::ssize_t n = b.shape(0);
  if (n == 0) throw py::value_error("bones is empty: a rod needs at least one joint");
  auto cond = checked_array<std::int32_t>(key_conditions, "key_conditions", -1, 0);
  const py::ssize_t m = cond.shape(0);
  const Vec3List dirs = to_points(key_directions, "key_directions", m);
  const QuatList krot = to_quats(key_rotations, "key_rotations", m);
  const std::vector<Real> speeds = to_vector(key_speeds, "key_speeds", m);
  const std::vector<Real> infl = to_vector(key_influences, "key_influences", m);
  const QuatList shapes = to_quats(key_shapes, "key_shapes", m * n);
  RodDefinition rod;
  rod.parent_bone = parent_bone;
  rod.reference_bone = reference_bone;
  rod.bones.assign(b.data(), b.data() + n);
  rod.geometry.offsets = to_points(offsets, "offsets", n + 1);
  rod.geometry.rest_rotations = to_quats(rest_rotations, "rest_rotations", n);
  for (auto [v, name] : {std::pair{stiffness, "stiffness"}, {damping, "damping"}, {gravity, "gravity"}, {radius, "radius"}}) {
    require_finite(v, name);
  }
  rod.params.stiffness = stiffness;
  rod.params.damping = damping;
  rod.params.gravity = gravity;
  rod.params.substeps = substeps;
  rod.params.iterations = iterations;
  rod.params.radius = radius;
  rod.params.wind = vec3(wind, "wind");
  rod.params.momentum_control = momentum_control;
  for (py::ssize_t i = 0; i < m; ++i) {
    RodKey key;
    const int c = cond.data()[i];
    if (c < 0 || c > 2) throw py::value_error("key_conditions must be 0 (VIEW), 1 (POSE) or 2 (SPEED)");
    key.condition = static_cast<Condition>(c);
    const std::string row = "[" + std::to_string(i) + "]";
    if (c == 0 && !(dirs[i].norm() >= 1e-9)) throw py::value_error("key_directions" + row + ": a view key has a zero or NaN direction");
    if (c == 1 && !(krot[i].norm() >= 1e-6)) throw py::value_error("key_rotations" + row + ": a pose key has a NaN or zero rotation");
    if (c == 2 && !(speeds[i] >= 0)) throw py::value_error("key_speeds" + row + ": a speed key needs a speed >= 0");
    key.direction = dirs[i];
    key.rotation = krot[i];
    key.speed = speeds[i];
    key.influence = infl[i];
    key.shape.assign(shapes.begin() + i * n, shapes.begin() + (i + 1) * n);
    rod.keys.push_back(std::move(key));
  }
  const ExclusiveUse use = exclusive(system);
  try {
    return system.add_rod(std::move(rod));
  } catch (const std::invalid_argument& e) {
    throw py::value_error(e.what());
  }
}

}  // namespace

void bind_rod(py::module_& m) {
  m.def(
      "view_weights",
      [](const py::handle& key_directions, const py::handle& influences, const py::handle& view) {
        const Vec3List d = to_points(key_directions, "key_directions");
        const std::vector<Real> p = to_vector(influences, "influences", static_cast<py::ssize_t>(d.size()));
        const Vec3 v = vec3(view, "view");
        try {
          return to_array(view_weights(d, p, v));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("key_directions"), py::arg("influences"), py::arg("view"),
      "Blend weights of view keys (docs/algorithms.md §3.2): w_i = ((dot(d_i, d) + 1) / 2)^p_i, normalised when\n"
      "their sum s >= 1, w_0 = 1 - s. key_directions (m, 3) float64, influences (m,) float64 > 0, view (3,)\n"
      "float64. Returns float64 (m + 1,), w[0] (the base shape) first.");

  m.def(
      "condition_weights",
      [](const py::handle& similarities, const py::handle& influences) {
        const std::vector<Real> s = to_vector(similarities, "similarities");
        const std::vector<Real> p = to_vector(influences, "influences", static_cast<py::ssize_t>(s.size()));
        try {
          return to_array(condition_weights(s, p));
        } catch (const std::invalid_argument& e) {
          throw py::value_error(e.what());
        }
      },
      py::arg("similarities"), py::arg("influences"),
      "The seed's weights for any condition: similarities in [0, 1] (m,), influences (m,) -> (m + 1,).");

  py::class_<RodSystem>(m, "RodSystem",
                        "Every rod of one armature. Frame inputs and outputs are flat arrays for all bones:\n"
                        "bone_matrices (B, 16) float32 as pose.bones.foreach_get('matrix') gives them,\n"
                        "rotations_out (B, 4) float32 (w, x, y, z) as foreach_get('rotation_quaternion').")
      .def(py::init([](std::size_t bone_count, unsigned threads) {
             if (threads > kMaxThreads) throw py::value_error("threads must be 0 (all cores) .. 1024");
             return std::make_unique<RodSystem>(bone_count, threads);
           }), py::arg("bone_count"), py::arg("threads") = 0)
      .def_property_readonly("rod_count", &RodSystem::rod_count)
      .def_property_readonly("bone_count", &RodSystem::bone_count)
      .def("add_rod", &add_rod, py::arg("parent_bone"), py::arg("reference_bone"), py::arg("bones"),
           py::arg("offsets"), py::arg("rest_rotations"), py::arg("stiffness") = 0.5, py::arg("damping") = 2.0,
           py::arg("gravity") = 1.0, py::arg("substeps") = 4, py::arg("iterations") = 1, py::arg("radius") = 0.01,
           py::arg("wind"), py::arg("key_conditions"), py::arg("key_directions"), py::arg("key_rotations"),
           py::arg("key_speeds"), py::arg("key_influences"), py::arg("key_shapes"),
           py::arg("momentum_control") = true,
           "Adds one rod (root first). offsets (n+1, 3): root head in the parent's rest frame, each next head in\n"
           "the previous bone's rest frame, the tip in the last bone's frame. rest_rotations (n, 4) (w, x, y, z):\n"
           "each bone's rest frame in its parent's. Keys: conditions (m,) int32 0 VIEW / 1 POSE / 2 SPEED,\n"
           "directions (m, 3), rotations (m, 4), speeds (m,), influences (m,), shapes (m * n, 4).")
      .def(
          "set_colliders",
          [](RodSystem& self, const py::handle& bones, const py::handle& capsule, const py::handle& offsets,
             const py::handle& radii, const py::handle& lengths) {
            auto b = checked_array<std::int32_t>(bones, "bones", -1, 0);
            const py::ssize_t c = b.shape(0);
            auto cap = checked_array<std::int32_t>(capsule, "capsule", c, 0);
            const Vec3List off = to_points(offsets, "offsets", c);
            auto rad = checked_array<double>(radii, "radii", c, 0);
            auto len = checked_array<double>(lengths, "lengths", c, 0);
            std::vector<ColliderDefinition> list;
            for (py::ssize_t i = 0; i < c; ++i) {
              ColliderDefinition d;
              d.bone = b.data()[i];
              d.capsule = cap.data()[i] != 0;
              d.offset = off[i];
              d.radius = rad.data()[i];
              d.length = len.data()[i];
              list.push_back(d);
            }
            const ExclusiveUse use = exclusive(self);
            try {
              self.set_colliders(std::move(list));
            } catch (const std::invalid_argument& e) {
              throw py::value_error(e.what());
            }
          },
          py::arg("bones"), py::arg("capsule"), py::arg("offsets"), py::arg("radii"), py::arg("lengths"),
          "Spheres (capsule 0) and capsules (1, along the bone's Y for `length`) that follow pose bones.")
      .def(
          "reset",
          [](RodSystem& self, const py::handle& bone_matrices, const py::handle& armature_matrix,
             const py::handle& camera, const py::handle& gravity, double time, const py::handle& rotations_out) {
            py::array_t<float> keep;
            const FrameInput in = frame_input(self, bone_matrices, armature_matrix, camera, gravity, time, 0.0, keep);
            auto out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
            no_overlap(out, "rotations_out", keep, "bone_matrices");
            const ExclusiveUse use = exclusive(self);
            float* out_data = out.mutable_data();
            py::gil_scoped_release release;
            self.reset(in, out_data);
          },
          py::arg("bone_matrices"), py::arg("armature_matrix"), py::arg("camera"), py::arg("gravity"),
          py::arg("time"), py::arg("rotations_out"),
          "Every rod at rest in its blended rest shape; writes the rod bones' rotations.")
      .def(
          "step",
          [](RodSystem& self, const py::handle& bone_matrices, const py::handle& armature_matrix,
             const py::handle& camera, const py::handle& gravity, double time, double frame_dt,
             const py::handle& rotations_out) {
            py::array_t<float> keep;
            const FrameInput in =
                frame_input(self, bone_matrices, armature_matrix, camera, gravity, time, frame_dt, keep);
            auto out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
            no_overlap(out, "rotations_out", keep, "bone_matrices");
            const ExclusiveUse use = exclusive(self);
            float* out_data = out.mutable_data();
            bool finite = true;
            {
              py::gil_scoped_release release;
              self.step(in, out_data);
              finite = rod_rows_finite(self, out_data);
              if (!finite) self.reset(in, out_data);  // leave the system usable, at rest
            }
            if (!finite) {
              throw py::value_error("the rods diverged (check gravity, wind, armature_matrix and frame_dt); "
                                    "they were reset to rest");
            }
          },
          py::arg("bone_matrices"), py::arg("armature_matrix"), py::arg("camera"), py::arg("gravity"),
          py::arg("time"), py::arg("frame_dt"), py::arg("rotations_out"),
          "Advances every rod by frame_dt seconds (camera: world position (3,) float64, or None).")
      .def("joint_positions", [](const RodSystem& self, std::size_t rod) {
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return points_array(self.joint_positions(rod));
           }, py::arg("rod"), "Joint positions (heads and tip, (n + 1, 3)) in armature space.")
      .def("joint_velocities", [](const RodSystem& self, std::size_t rod) {
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return points_array(self.joint_velocities(rod));
           }, py::arg("rod"))
      .def("energy", [](const RodSystem& self, std::size_t rod, const py::handle& gravity) {
             const Vec3 g = vec3(gravity, "gravity");
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             const RodEnergy e = self.energy(rod, g);
             py::dict out;
             out["kinetic"] = e.kinetic;
             out["gravitational"] = e.gravitational;
             out["shape_matching"] = e.shape_matching;
             out["total"] = e.total();
             return out;
           }, py::arg("rod"), py::arg("gravity"),
           "The rod's energy per unit particle mass (J/kg) under gravity (3,) in armature space: kinetic,\n"
           "gravitational, shape_matching and their total (docs/algorithms.md §3.3).")
      .def("weights", [](const RodSystem& self, std::size_t rod) {
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return to_array(self.weights(rod));
           }, py::arg("rod"), "This frame's weights (m + 1,), base shape first.")
      .def("reference_speed", [](const RodSystem& self, std::size_t rod) {
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return self.reference_speed(rod);
           }, py::arg("rod"))
      .def("rest_shape", [](const RodSystem& self, std::size_t rod) {
             const ExclusiveUse use = exclusive(self);
             if (rod >= self.rod_count()) throw py::index_error("rod index out of range");
             return quats_array(self.rest_shape(rod));
           }, py::arg("rod"), "The rest shape blended this frame, (n, 4) rotations.")
      .def("save_state", [](const RodSystem& self) {
             const ExclusiveUse use = exclusive(self);
             return to_array(self.save_state());
           },
           "The full simulation state (float64), for exact per-frame caches.")
      .def("load_state", [](RodSystem& self, const py::handle& state) {
             auto s = checked_array<double>(state, "state", -1, 0);
             const ExclusiveUse use = exclusive(self);
             try {
               self.load_state(std::vector<Real>(s.data(), s.data() + s.shape(0)));
             } catch (const std::invalid_argument& e) {
               throw py::value_error(e.what());
             }
           }, py::arg("state"))
      // The exact per-frame cache (scrubbing), kept natively: see rod/frame_cache.hpp.
      .def("store_frame", [](RodSystem& self, int frame, const py::handle& rotations) {
             auto r = checked_array<float>(rotations, "rotations", static_cast<py::ssize_t>(self.bone_count()), 4);
             const ExclusiveUse use = exclusive(self);
             const float* data = r.data();
             py::gil_scoped_release release;
             self.store_frame(frame, data);
           }, py::arg("frame"), py::arg("rotations"),
           "Caches this frame: the full state and the rod bones' rows of rotations (B, 4).")
      .def("recall_frame", [](RodSystem& self, int frame, const py::handle& rotations_out, bool load_state) {
             float* out_data = nullptr;
             py::array_t<float> out;
             if (!rotations_out.is_none()) {
               out = checked_output<float>(rotations_out, "rotations_out", static_cast<py::ssize_t>(self.bone_count()), 4);
               out_data = out.mutable_data();
             }
             const ExclusiveUse use = exclusive(self);
             py::gil_scoped_release release;
             return self.recall_frame(frame, out_data, load_state);
           }, py::arg("frame"), py::arg("rotations_out") = py::none(), py::arg("load_state") = true,
           "Loads a cached frame's state (if load_state) and writes its rod-bone rows into rotations_out;\n"
           "False when the frame is not cached.")
      .def("cached_frames", [](RodSystem& self) {
             const ExclusiveUse use = exclusive(self);
             return self.frame_cache().frames();
           },
           "The cached frames, ascending.")
      .def("latest_cached_frame_before", [](RodSystem& self, int frame) {
             const ExclusiveUse use = exclusive(self);
             return self.frame_cache().latest_before(frame);
           }, py::arg("frame"), "The latest cached frame before `frame`, or None.")
      .def("clear_cache", [](RodSystem& self) {
             const ExclusiveUse use = exclusive(self);
             self.frame_cache().clear();
           })
      .def_property(
          "cache_budget", [](RodSystem& self) {
            const ExclusiveUse use = exclusive(self);
            return self.frame_cache().budget();
          },
          [](RodSystem& self, std::size_t bytes) {
            const ExclusiveUse use = exclusive(self);
            self.frame_cache().set_budget(bytes);
          },
          "Bytes the frame cache may hold (0: unbounded). Over it, frames thin out to checkpoints\n"
          "(see rod/frame_cache.hpp): recall_frame() is then False for a dropped frame, which is\n"
          "recomputed exactly from latest_cached_frame_before() by stepping on.")
      .def_property_readonly("cache_bytes", [](RodSystem& self) {
                               const ExclusiveUse use = exclusive(self);
                               return self.frame_cache().bytes();
                             },
                             "Bytes the frame cache holds now.")
      .def_property_readonly("cache_checkpoint_interval", [](RodSystem& self) {
                               const ExclusiveUse use = exclusive(self);
                               return self.frame_cache().checkpoint_interval();
                             },
                             "Frames between the checkpoints kept once the budget thinned the cache.")
      .def("cached_state", [](RodSystem& self, int frame) -> py::object {
             const ExclusiveUse use = exclusive(self);
             const FrameCache::Entry* e = self.frame_cache().find(frame);
             if (e == nullptr) return py::none();
             py::array_t<double> out(static_cast<py::ssize_t>(e->state_size));
             std::copy_n(e->state.get(), e->state_size, out.mutable_data());
             return out;
           }, py::arg("frame"), "A cached frame's full state (as save_state gives it), or None.")
      .def("cached_rotations", [](RodSystem& self, int frame) -> py::object {
             const ExclusiveUse use = exclusive(self);
             const FrameCache::Entry* e = self.frame_cache().find(frame);
             if (e == nullptr) return py::none();
             py::array_t<float> out({static_cast<py::ssize_t>(e->rotations.size() / 4), py::ssize_t(4)});
             std::copy(e->rotations.begin(), e->rotations.end(), out.mutable_data());
             return out;
           }, py::arg("frame"), "A cached frame's rod-bone rotations (rod bones, 4), rod by rod, root first.");

  py::class_<RodStepAhead>(m, "RodStepAhead",
                           "A RodSystem's next frame stepped on a worker thread while Python goes on (the GIL\n"
                           "released): start() copies the system's state and the inputs and returns at once;\n"
                           "finish() waits and writes the rod bones' rotations; adopt() gives the system the\n"
                           "stepped state, bit for bit what its own step() would have made, only while it\n"
                           "still holds the state the step started from (docs/algorithms.md §3.7).")
      .def(py::init([](unsigned threads) {
             if (threads > kMaxThreads) throw py::value_error("threads must be 0 (all cores) .. 1024");
             return std::make_unique<RodStepAhead>(threads);
           }), py::arg("threads") = 0)
      .def(
          "start",
          [](RodStepAhead& self, const RodSystem& system, const py::handle& bone_matrices,
             const py::handle& armature_matrix, const py::handle& camera, const py::handle& gravity, double time,
             double frame_dt, const py::handle& rotations) {
            py::array_t<float> keep;
            const FrameInput in =
                frame_input(system, bone_matrices, armature_matrix, camera, gravity, time, frame_dt, keep);
            py::array_t<float> rows;
            if (!rotations.is_none()) {
              rows = checked_array<float>(rotations, "rotations", static_cast<py::ssize_t>(system.bone_count()), 4);
            }
            const ExclusiveUse use_system = exclusive(system);
            const ExclusiveUse use(&self, "RodStepAhead");
            const float* rows_data = rotations.is_none() ? nullptr : rows.data();
            py::gil_scoped_release release;
            self.start(system, in, rows_data);
          },
          py::arg("system"), py::arg("bone_matrices"), py::arg("armature_matrix"), py::arg("camera"),
          py::arg("gravity"), py::arg("time"), py::arg("frame_dt"), py::arg("rotations") = py::none(),
          "Starts system.step(...) with these inputs on a copy of its state; returns at once. With rotations\n"
          "(B, 4) float32, the rotations the system's state was written with, the thread first makes the\n"
          "frame-cache snapshot of that state for store().")
      .def(
          "store",
          [](RodStepAhead& self, RodSystem& system, int frame) {
            const ExclusiveUse use_system = exclusive(system);
            const ExclusiveUse use(&self, "RodStepAhead");
            py::gil_scoped_release release;
            return self.store(system, frame);
          },
          py::arg("system"), py::arg("frame"),
          "system.store_frame(frame, rotations) with the snapshot start() had made on its thread, when the\n"
          "system still holds the state it was made of; waits for the snapshot only. False, nothing cached,\n"
          "otherwise.")
      .def(
          "finish",
          [](RodStepAhead& self, const py::handle& rotations_out) {
            auto out = checked_output<float>(rotations_out, "rotations_out", -1, 4);
            const ExclusiveUse use(&self, "RodStepAhead");
            if (self.started() && static_cast<std::size_t>(out.shape(0)) != self.bone_count()) {
              throw py::value_error("rotations_out must have one row per bone of the stepped system");
            }
            float* out_data = out.mutable_data();
            py::gil_scoped_release release;
            return self.finish(out_data);
          },
          py::arg("rotations_out"),
          "Steps the rods the thread has not taken yet (the GIL released), then waits for it; True when the\n"
          "step ran and stayed finite: the rod bones' rows of rotations_out (B, 4) float32 then hold its\n"
          "rotations. False: nothing was written (none started, or it diverged).")
      .def(
          "adopt",
          [](RodStepAhead& self, RodSystem& system) {
            const ExclusiveUse use_system = exclusive(system);
            const ExclusiveUse use(&self, "RodStepAhead");
            py::gil_scoped_release release;
            return self.adopt(system);
          },
          py::arg("system"),
          "After finish(): the system takes the stepped state when it is the system the step started\n"
          "from and holds the state it started from. False, and nothing changes, otherwise.")
      .def_property_readonly("started", &RodStepAhead::started, "A step runs or waits to be finished.")
      .def_property_readonly("caller_share", &RodStepAhead::caller_share,
                             "The share of the rods the last finish() stepped itself (0: the thread had\n"
                             "finished them; 1: it had not begun), in [0, 1].");
}

}  // namespace kodawari::bind
