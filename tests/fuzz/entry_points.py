"""Every kodawari_native entry point with a valid call the fuzzer mutates.

Each Target builds fresh, valid keyword arguments (so a mutation reaches deep into the
code, not only the first check) and calls the entry point with them. `outputs` names
arguments the call writes into; `alias` pairs (output, input) the fuzzer may make
share memory. Objects with state (RodSystem, AxisBinding) are built anew per case."""

import functools
import os
import re
import sys
from collections.abc import Callable
from dataclasses import dataclass, field

import kodawari_native as kn
import numpy as np

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.append(os.path.join(os.path.dirname(HERE), "python"))
from gait_rigs import horse_rig


@dataclass
class Target:
    name: str  # as listed by public_entry_points()
    make_args: Callable[[], dict]
    call: Callable[..., object]
    outputs: tuple = ()
    alias: tuple = ()  # (output, input) pairs of the same dtype
    examples: int = 60
    # words an error may name besides the arguments
    extra_names: tuple = field(default_factory=tuple)
    generic: bool = False  # no valid call known: called with random positional arguments

    def __post_init__(self):  # a gait table's rows and columns name what is wrong in table['gaits']
        if not self.generic and "table" in self.make_args():
            self.extra_names = (
                tuple(self.extra_names) + tuple(kn.GAIT_COLUMNS) + tuple(kn.GAIT_NAMES)
            )


def axis(n=6):
    s = np.linspace(0.0, 4.0, n)
    return np.column_stack([s, 0.3 * np.sin(s), 0.1 * np.cos(s)])


def mesh(n=30):
    rng = np.random.default_rng(1)
    return (rng.random((n, 3)) * [4.0, 0.6, 0.6] - [0.0, 0.3, 0.3]).astype(np.float32)


def _binding():
    return kn.ffd_bind(axis(), mesh())


def _chain_system(bones=4, bone_count=6):
    system = kn.RodSystem(bone_count, 1)
    system.add_rod(
        0,
        0,
        np.arange(1, bones + 1, dtype=np.int32),
        _offsets(bones),
        np.tile([1.0, 0, 0, 0], (bones, 1)),
        wind=np.zeros(3),
        **_keys(bones),
    )
    out = np.tile(np.array([1.0, 0, 0, 0], np.float32), (bone_count, 1))
    system.reset(_matrices(bone_count), np.eye(4), None, np.array([0.0, 0.0, -9.81]), 0.0, out)
    return system


def _offsets(bones):
    return np.array([(0.0, 0.2, 0.0)] + [(0.0, 0.1, 0.0)] * bones)


def _keys(bones, m=1):
    return {
        "key_conditions": np.zeros(m, np.int32),
        "key_directions": np.tile([0.0, 1.0, 0.0], (m, 1)),
        "key_rotations": np.tile([1.0, 0, 0, 0], (m, 1)),
        "key_speeds": np.zeros(m),
        "key_influences": np.full(m, 2.0),
        "key_shapes": np.tile([0.96, 0.28, 0, 0], (m * bones, 1)),
    }


def _matrices(bone_count):
    m = np.tile(np.eye(4), (bone_count, 1, 1))
    m[0, :3, 3] = (0.1, 0.0, 0.3)
    return np.ascontiguousarray(m.transpose(0, 2, 1).reshape(-1, 16), dtype=np.float32)


def _frame_args(bone_count=6, with_dt=True):
    args = {
        "bone_matrices": _matrices(bone_count),
        "armature_matrix": np.eye(4),
        "camera": np.array([0.0, -5.0, 1.0]),
        "gravity": np.array([0.0, 0.0, -9.81]),
        "time": 0.04,
    }
    if with_dt:
        args["frame_dt"] = 1 / 24
    args["rotations_out"] = np.tile(np.array([1.0, 0, 0, 0], np.float32), (bone_count, 1))
    return args


def _ground():
    x = np.linspace(-3.0, 3.0, 7)
    heights = (0.05 * np.sin(x)[None, :] * np.cos(x)[:, None]).reshape(-1)
    return {"heights": heights, "nx": 7, "ny": 7, "x0": -3.0, "y0": -3.0, "cell": 1.0}


def _gait_bake_args():
    frames = 10
    return {
        "rig": horse_rig(),
        "table": kn.gait_horse_table(),
        "target_speed": np.linspace(0.5, 3.0, frames),
        "gait_mode": np.full(frames, -1.0),
        "fps": 24.0,
        "acceleration": 3.0,
        "ccd_iterations": 8,
        "path": np.array([[0.0, 0.0, 0.0], [0.0, -3.0, 0.0], [1.0, -6.0, 0.0]]),
        "ground": _ground(),
    }


def _chain():
    return {
        "lengths": np.array([0.4, 0.4, 0.3]),
        "rest_direction": np.full(3, -np.pi / 2),
        "limit_min": np.full(3, -2.0),
        "limit_max": np.full(3, 2.0),
        "stiffness": np.array([0.3, 0.6, 1.0]),
    }


def _method(make_self, name, probe=None):
    """Calls make_self().name(**kwargs); with `probe`, returns (result, probe(self)) so
    the object's state after the call is checked too."""

    def call(**kwargs):
        obj = make_self()
        result = getattr(obj, name)(**kwargs)
        return result if probe is None else (result, probe(obj))

    return call


def _rod_state(system):
    return system.save_state(), [system.joint_positions(r) for r in range(system.rod_count)]


def _rod_method(name):
    return _method(_chain_system, name, _rod_state)


def _cached_rod_method(name):
    def make_self():
        system = _chain_system()
        out = np.tile(np.array([1.0, 0, 0, 0], np.float32), (6, 1))
        system.store_frame(3, out)
        return system

    return _method(make_self, name, _rod_state)


def _ahead_args(with_rotations=True):
    """RodStepAhead.start's arguments: a fresh chain system and a frame's inputs."""
    args = _frame_args()
    out = args.pop("rotations_out")
    args["system"] = _chain_system()
    if with_rotations:
        args["rotations"] = out
    return args


def _step_ahead(call):
    """Starts a step ahead, then calls call(ahead, system, **kwargs): (result, the system's
    state), so what finish/adopt/store leave behind is checked too."""

    def run(**kwargs):
        system = _chain_system()
        ahead = kn.RodStepAhead(threads=1)
        start = _frame_args()
        out = start.pop("rotations_out")
        ahead.start(system=system, rotations=out, **start)
        return call(ahead, system, **kwargs), _rod_state(system)

    return run


def _ahead_start(system, **kwargs):
    ahead = kn.RodStepAhead(threads=1)
    ahead.start(system=system, **kwargs)
    out = np.zeros((6, 4), np.float32)
    return ahead.finish(out), out, ahead.adopt(system), _rod_state(system)


def _set_cache_budget(budget):
    """Sets the budget, then fills the cache past it: the thinning must keep a usable cache."""
    system = _chain_system()
    system.cache_budget = budget
    out = np.tile(np.array([1.0, 0, 0, 0], np.float32), (6, 1))
    args = _frame_args()
    for frame in range(1, 30):
        system.step(
            args["bone_matrices"], np.eye(4), None, args["gravity"], frame / 24, 1 / 24, out
        )
        system.store_frame(frame, out)
    return system.cache_budget, system.cache_bytes, system.cached_frames(), _rod_state(system)


def _fin_part_args():
    heights = np.repeat(np.linspace(0.0, 0.1, 6), 5)
    along = np.tile(np.linspace(0.0, 0.2, 5), 6)
    return {
        "points": np.stack([along, np.zeros_like(along), heights], axis=1).astype(np.float32),
        "reach": heights.copy(),
        "weight": np.ones_like(heights),
        "root": np.array([0.1, 0.0, 0.0]),
        "outward": np.array([0.0, 0.0, 1.0]),
        "tangent": np.array([1.0, 0.0, 0.0]),
        "side": np.array([0.0, 1.0, 0.0]),
        "up": np.array([0.0, 0.0, 1.0]),
        "height": 0.1,
        "base_length": 0.2,
        "base_front": 0.0,
    }


def _fin_part():
    return kn.FinPart(**_fin_part_args())


def _displace_args():
    probes = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [0, 0, 1]], dtype=np.float32)
    return {
        "motion": "FLAP",
        "amplitude": 0.5,
        "phase": 1.2,
        "feathering": 0.1,
        "wavelength": 1.0,
        "feather_on_power": False,
        "probes_rest": probes,
        "probes_now": probes[[0, 2, 1, 3]].copy(),
        "out": np.zeros((30, 3), np.float32),
    }


@functools.cache
def _disc():
    """tests/python's round fish with a dorsal plate: vertices, edges, fin mask, axis coordinates."""
    from test_swim_kernels import _disc_fish

    vertices, edges, fin = _disc_fish()
    coords = np.empty_like(vertices)
    axis2 = np.array([[0.5, 0, 0], [-0.5, 0, 0]], dtype=np.float64)
    kn.swim_fin_axis_coordinates(
        axis2, np.array([0.0, 0.0, 1.0]), vertices, coords, 0, len(vertices)
    )
    return vertices, edges, fin, coords


def _fin_finder_args():
    vertices, edges, _, coords = _disc()
    return {
        "coordinates": coords.copy(),
        "edges": edges.copy(),
        "slices": 48,
        "sectors": 32,
        "outside": 1.2,
        "margin": 0.004,
        "min_vertices": 8,
    }


def _axis_coordinates_args():
    vertices = _disc()[0]
    return {
        "axis_points": np.array([[0.5, 0, 0], [0.0, 0.05, 0], [-0.5, 0, 0]]),
        "up": np.array([0.0, 0.0, 1.0]),
        "vertices": vertices.copy(),
        "out": np.zeros_like(vertices),
        "begin": 0,
        "end": len(vertices),
    }


def _fin_reach_args():
    vertices, edges, fin, _ = _disc()
    squash = np.zeros((len(vertices), 9), dtype=np.float32)
    squash[fin] = np.outer([1.0, 0, 0], [1.0, 0, 0]).reshape(-1)
    return {
        "vertices": vertices.copy(),
        "edges": edges.copy(),
        "in_fin": fin.copy(),
        "seed_radius": 1e-6,
        "squash": squash,
    }


def _fin_args():
    return {
        "rest_points": np.column_stack([np.zeros(5), np.linspace(0, 0.4, 5), np.zeros(5)]),
        "tangent": np.array([0.0, 1.0, 0.0]),
        "side": np.array([1.0, 0.0, 0.0]),
        "up": np.array([0.0, 0.0, 1.0]),
        "motion": "FLAP",
        "amplitude": 0.5,
        "phase": 0.3,
        "feathering": 0.2,
        "wavelength": 1.0,
        "fixed_count": 2,
        "feather_on_power": False,
    }


TARGETS = [
    # --- FFD
    Target(
        "ffd_bind",
        lambda: {
            "control_points": axis(),
            "vertices": mesh(),
            "twist": np.zeros(6),
            "up": np.array([0.0, 0.0, 1.0]),
        },
        kn.ffd_bind,
        examples=120,
    ),
    Target(
        "AxisBinding.deform",
        lambda: {
            "control_points": axis() * 1.1,
            "out": np.zeros((30, 3), np.float32),
            "twist": np.linspace(0, 1, 6),
            "up": None,
            "threads": 1,
        },
        _method(_binding, "deform"),
        outputs=("out",),
        examples=100,
    ),
    Target("AxisBinding.t", dict, lambda: _binding().t, examples=1),
    Target("AxisBinding.u", dict, lambda: _binding().u, examples=1),
    Target("AxisBinding.v", dict, lambda: _binding().v, examples=1),
    Target("AxisBinding.w", dict, lambda: _binding().w, examples=1),
    Target("AxisBinding.count", dict, lambda: _binding().count, examples=1),
    Target(
        "AxisBinding.control_point_count", dict, lambda: _binding().control_point_count, examples=1
    ),
    Target(
        "ffd_frames",
        lambda: {"control_points": axis(), "twist": None, "up": None, "samples": 8},
        kn.ffd_frames,
    ),
    Target(
        "curve_points",
        lambda: {"control_points": axis(), "t": np.linspace(0, 1, 5)},
        kn.curve_points,
    ),
    Target("curve_length", lambda: {"control_points": axis()}, kn.curve_length),
    Target(
        "preserve_lengths",
        lambda: {
            "points": axis(),
            "rest_lengths": np.full(5, 0.8),
            "moved_index": 2,
            "arc_length": 4.2,
        },
        kn.preserve_lengths,
    ),
    Target(
        "preserve_lengths_from_head",
        lambda: {"points": axis(), "rest_lengths": np.full(5, 0.8), "arc_length": None},
        kn.preserve_lengths_from_head,
    ),
    # --- swim
    Target(
        "swim_body_axis",
        lambda: {
            "rest_points": axis(),
            "bend_direction": np.array([0.0, 1.0, 0.0]),
            "body_length": 4.0,
            "phase": 0.5,
            "wavelength": 1.0,
            "amplitude": 0.1,
            "amplitude_head": 0.02,
            "envelope_start": 0.2,
            "envelope_power": 2.0,
            "phase_offset": 0.0,
            "preserve_length": True,
        },
        kn.swim_body_axis,
    ),
    Target(
        "swim_wave_envelope",
        lambda: {
            "s": 0.5,
            "amplitude": 0.1,
            "amplitude_head": 0.02,
            "envelope_start": 0.2,
            "envelope_power": 2.0,
        },
        kn.swim_wave_envelope,
    ),
    Target("swim_fin_axis", _fin_args, kn.swim_fin_axis, examples=80),
    Target(
        "swim_flap_stroke_direction",
        lambda: {
            "fin_axis": np.array([1.0, 0.2, 0.0]),
            "tangent": np.array([0.0, 1.0, 0.0]),
            "side": np.array([1.0, 0.0, 0.0]),
            "up": np.array([0.0, 0.0, 1.0]),
        },
        kn.swim_flap_stroke_direction,
    ),
    Target(
        "swim_accumulate_phase",
        lambda: {"frequencies": np.linspace(0.5, 2.0, 12), "dt": 1 / 24, "phase0": 0.0},
        kn.swim_accumulate_phase,
    ),
    Target(
        "swim_speed",
        lambda: {
            "mode": "STROUHAL",
            "body_length": 1.0,
            "frequency": 2.0,
            "amplitude": 0.1,
            "strouhal": 0.3,
        },
        kn.swim_speed,
    ),
    Target("swim_bainbridge_applies", lambda: {"frequency": 6.0}, kn.swim_bainbridge_applies),
    Target(
        "swim_fin_axis_coordinates",
        _axis_coordinates_args,
        kn.swim_fin_axis_coordinates,
        outputs=("out",),
        alias=(("out", "vertices"),),
        examples=60,
    ),
    Target("swim_find_fins", _fin_finder_args, kn.swim_find_fins, examples=60),
    Target(
        "swim_nearest_distances",
        lambda: {"points": _disc()[0][:50].copy(), "cloud": _disc()[0].copy()},
        kn.swim_nearest_distances,
    ),
    Target("swim_fin_reach", _fin_reach_args, kn.swim_fin_reach, examples=60),
    Target("FinPart", _fin_part_args, kn.FinPart, examples=80),
    Target(
        "FinPart.displace",
        _displace_args,
        _method(_fin_part, "displace"),
        outputs=("out",),
        examples=80,
    ),
    Target(
        "FinPart.swing_direction",
        lambda: {"motion": "FLAP"},
        _method(_fin_part, "swing_direction"),
        examples=20,
    ),
    Target("FinPart.count", dict, lambda: _fin_part().count, examples=1),
    Target("FinPart.max_roll", dict, lambda: _fin_part().max_roll, examples=1),
    Target("FinPart.max_feather", dict, lambda: _fin_part().max_feather, examples=1),
    Target("FinPart.max_undulation", dict, lambda: _fin_part().max_undulation, examples=1),
    # --- rod
    Target(
        "view_weights",
        lambda: {
            "key_directions": np.array([[0.0, 1.0, 0.0], [1.0, 0.0, 0.0]]),
            "influences": np.array([2.0, 3.0]),
            "view": np.array([0.3, 0.9, 0.1]),
        },
        kn.view_weights,
    ),
    Target(
        "condition_weights",
        lambda: {"similarities": np.array([0.2, 0.9]), "influences": np.array([2.0, 1.0])},
        kn.condition_weights,
    ),
    Target("RodSystem", lambda: {"bone_count": 6, "threads": 1}, kn.RodSystem),
    Target("AxisBinding", dict, kn.AxisBinding, examples=1, extra_names=("constructor",)),
    Target(
        "RodSystem.add_rod",
        lambda: dict(
            parent_bone=0,
            reference_bone=0,
            bones=np.array([4, 5], np.int32),
            offsets=_offsets(2),
            rest_rotations=np.tile([1.0, 0, 0, 0], (2, 1)),
            stiffness=0.5,
            damping=1.0,
            gravity=1.0,
            substeps=2,
            iterations=1,
            radius=0.01,
            wind=np.array([0.5, 0.0, 0.0]),
            momentum_control=True,
            **_keys(2),
        ),
        _method(lambda: kn.RodSystem(6, 1), "add_rod"),
        examples=100,
    ),
    Target(
        "RodSystem.set_colliders",
        lambda: {
            "bones": np.array([0], np.int32),
            "capsule": np.array([1], np.int32),
            "offsets": np.zeros((1, 3)),
            "radii": np.array([0.05]),
            "lengths": np.array([0.2]),
        },
        _rod_method("set_colliders"),
    ),
    Target(
        "RodSystem.reset",
        lambda: _frame_args(with_dt=False),
        _rod_method("reset"),
        outputs=("rotations_out",),
        alias=(("rotations_out", "bone_matrices"),),
        examples=80,
    ),
    Target(
        "RodSystem.step",
        _frame_args,
        _rod_method("step"),
        outputs=("rotations_out",),
        alias=(("rotations_out", "bone_matrices"),),
        examples=120,
    ),
    Target(
        "RodSystem.joint_positions",
        lambda: {"rod": 0},
        _rod_method("joint_positions"),
        examples=10,
    ),
    Target(
        "RodSystem.joint_velocities",
        lambda: {"rod": 0},
        _rod_method("joint_velocities"),
        examples=10,
    ),
    Target("RodSystem.weights", lambda: {"rod": 0}, _rod_method("weights"), examples=10),
    Target(
        "RodSystem.energy",
        lambda: {"rod": 0, "gravity": np.array([0.0, 0.0, -9.81])},
        _rod_method("energy"),
        examples=20,
    ),
    Target(
        "RodSystem.reference_speed",
        lambda: {"rod": 0},
        _rod_method("reference_speed"),
        examples=10,
    ),
    Target("RodSystem.rest_shape", lambda: {"rod": 0}, _rod_method("rest_shape"), examples=10),
    Target("RodSystem.rod_count", dict, lambda: _chain_system().rod_count, examples=1),
    Target("RodSystem.bone_count", dict, lambda: _chain_system().bone_count, examples=1),
    Target("RodSystem.save_state", dict, _rod_method("save_state"), examples=1),
    Target(
        "RodSystem.load_state",
        lambda: {"state": _chain_system().save_state()},
        _rod_method("load_state"),
        examples=60,
    ),
    Target(
        "RodSystem.store_frame",
        lambda: {"frame": 3, "rotations": np.tile(np.array([1.0, 0, 0, 0], np.float32), (6, 1))},
        _rod_method("store_frame"),
    ),
    Target(
        "RodSystem.recall_frame",
        lambda: {"frame": 3, "rotations_out": np.zeros((6, 4), np.float32), "load_state": True},
        _cached_rod_method("recall_frame"),
        outputs=("rotations_out",),
    ),
    Target("RodSystem.cached_frames", dict, _cached_rod_method("cached_frames"), examples=1),
    Target(
        "RodSystem.latest_cached_frame_before",
        lambda: {"frame": 5},
        _cached_rod_method("latest_cached_frame_before"),
        examples=20,
    ),
    Target("RodSystem.clear_cache", dict, _cached_rod_method("clear_cache"), examples=1),
    Target(
        "RodSystem.cached_state",
        lambda: {"frame": 3},
        _cached_rod_method("cached_state"),
        examples=20,
    ),
    Target(
        "RodSystem.cached_rotations",
        lambda: {"frame": 3},
        _cached_rod_method("cached_rotations"),
        examples=20,
    ),
    Target("RodSystem.cache_budget", lambda: {"budget": 4096}, _set_cache_budget, examples=40),
    Target("RodSystem.cache_bytes", dict, lambda: _chain_system().cache_bytes, examples=1),
    Target(
        "RodSystem.cache_checkpoint_interval",
        dict,
        lambda: _chain_system().cache_checkpoint_interval,
        examples=1,
    ),
    # --- the next frame stepped ahead (RodStepAhead)
    Target("RodStepAhead", lambda: {"threads": 1}, kn.RodStepAhead, examples=20),
    Target(
        "RodStepAhead.start",
        _ahead_args,
        _ahead_start,
        alias=(("rotations", "bone_matrices"),),
        examples=80,
        extra_names=("system",),
    ),
    Target(
        "RodStepAhead.finish",
        lambda: {"rotations_out": np.zeros((6, 4), np.float32)},
        _step_ahead(lambda ahead, system, **kw: ahead.finish(**kw)),
        outputs=("rotations_out",),
    ),
    Target(
        "RodStepAhead.adopt",
        dict,
        _step_ahead(
            lambda ahead, system: (ahead.finish(np.zeros((6, 4), np.float32)), ahead.adopt(system))
        ),
        examples=5,
    ),
    Target(
        "RodStepAhead.store",
        lambda: {"frame": 3},
        _step_ahead(
            lambda ahead, system, **kw: (ahead.store(system, **kw), system.cached_frames())
        ),
        examples=30,
    ),
    Target(
        "RodStepAhead.caller_share",
        dict,
        _step_ahead(
            lambda ahead, system: (ahead.finish(np.zeros((6, 4), np.float32)), ahead.caller_share)
        ),
        examples=1,
    ),
    Target(
        "RodStepAhead.started",
        dict,
        _step_ahead(lambda ahead, system: ahead.started),
        examples=1,
    ),
    # --- gait
    Target("gait_horse_table", lambda: {"leg_length": 1.4}, kn.gait_horse_table, examples=30),
    Target(
        "gait_duty_factor",
        lambda: {"table": kn.gait_horse_table(), "gait": 3, "speed": 9.0, "leg_length": 1.4},
        kn.gait_duty_factor,
    ),
    Target(
        "gait_check_speeds",
        lambda: {
            "table": kn.gait_horse_table(),
            "speed": np.linspace(0.0, 12.0, 8),
            "gait_mode": np.array([-1.0, -1, 0, 1, 2, 3, 4, -1]),
            "leg_length": 1.4,
        },
        kn.gait_check_speeds,
    ),
    Target("gait_validate_table", lambda: {"table": kn.gait_horse_table()}, kn.gait_validate_table),
    Target("gait_validate_rig", lambda: {"rig": horse_rig()}, kn.gait_validate_rig, examples=80),
    Target(
        "gait_leg_phases", lambda: {"table": kn.gait_horse_table(), "gait": 2}, kn.gait_leg_phases
    ),
    Target(
        "gait_seed_swing_distance",
        lambda: {
            "speed_new": 3.0,
            "speed_old": 2.0,
            "swing_time": 0.3,
            "duty_factor": 0.6,
            "since_change": 0.1,
            "added_time": 0.05,
        },
        kn.gait_seed_swing_distance,
    ),
    Target(
        "gait_table_speed_max",
        lambda: {"table": kn.gait_horse_table(), "gait": -1, "leg_length": 1.4},
        kn.gait_table_speed_max,
    ),
    Target(
        "gait_select",
        lambda: {"table": kn.gait_horse_table(), "speed": 4.0, "current": 0, "leg_length": 1.4},
        kn.gait_select,
    ),
    Target(
        "gait_ccd_solve",
        lambda: {
            "chain": _chain(),
            "target": np.array([0.2, -0.9]),
            "angles": np.zeros(3),
            "iterations": 20,
            "tolerance": 1e-4,
        },
        kn.gait_ccd_solve,
        examples=80,
    ),
    Target("gait_bake", _gait_bake_args, kn.gait_bake, examples=70),
    # The dict arguments alone, each mutated more often than among the nine arguments.
    *[
        Target(
            f"gait_bake:{key}",
            lambda key=key: {key: _gait_bake_args()[key]},
            lambda key=key, **kw: kn.gait_bake(**{**_gait_bake_args(), **kw}),
            examples=60,
        )
        for key in ("ground", "rig", "table")
    ],
    Target(
        "gait_forward_kinematics",
        lambda: {
            "rig": horse_rig(),
            "angles": np.zeros((3, 16)),
            "body_location": np.zeros((3, 3)),
            "body_rotation": np.tile([1.0, 0, 0, 0], (3, 1)),
        },
        kn.gait_forward_kinematics,
        examples=60,
    ),
    Target(
        "pose_forward_kinematics",
        lambda: {
            "parents": np.array([-1, 0, 1], np.int32),
            "rest": np.tile(np.eye(4).reshape(-1), (3, 1)),
            "channels": np.tile([0.0, 0.1, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0, 1.0, 1.0], (3, 1)),
            "rotation_modes": np.array([0, 1, -1], np.int32),
            "inherit_rotation": np.array([1, 0, 1], np.int32),
            "inherit_scale": np.array([0, 1, 3], np.int32),  # AVERAGE under a hinge
        },
        kn.pose_forward_kinematics,
        examples=60,
    ),
]


def public_entry_points():
    """Every public callable of the module: functions, classes, and the classes'
    methods and properties, as "name" or "Class.member"."""
    names = []
    for name in dir(kn):
        if name.startswith("_"):
            continue
        obj = getattr(kn, name)
        if isinstance(obj, type):
            names.append(name)
            names += [f"{name}.{m}" for m in dir(obj) if not m.startswith("_")]
        elif callable(obj):
            names.append(name)
    return names


def signature_names(func):
    """Argument names from pybind11's signature line: "f(a: int, b: object) -> None"."""
    first = (getattr(func, "__doc__", None) or "").splitlines()
    return tuple(re.findall(r"(\w+): ", first[0].split(") ->")[0])) if first else ()


_INSTANCES = {"RodSystem": _chain_system, "AxisBinding": _binding, "FinPart": _fin_part}


def generic_target(name):
    """A Target for an entry point nobody wrote a valid call for yet (e.g. one added
    after this file): random positional arguments, same oracle. None when it cannot
    be reached (a member of a class this file does not know how to build)."""
    if "." in name:
        cls, member = name.split(".", 1)
        if cls not in _INSTANCES:
            return None
        make_self = _INSTANCES[cls]
        attr = getattr(getattr(kn, cls), member)
        names = signature_names(attr) if callable(attr) else ()

        def call(*args):
            value = getattr(make_self(), member)
            return value(*args) if callable(value) else value
    else:
        call = getattr(kn, name)
        names = signature_names(call.__init__ if isinstance(call, type) else call)
    return Target(name, dict, call, examples=60, extra_names=names, generic=True)


def all_targets():
    """TARGETS, plus a generic target for every public entry point they miss."""
    covered = {t.name for t in TARGETS}
    extra = [generic_target(n) for n in public_entry_points() if n not in covered]
    return TARGETS + [t for t in extra if t is not None]
