"""Fish swim operators as a user drives them: timing, bake, save/reload, undo, remove (issue 3)."""

import os

import bpy
import numpy as np
import pytest
from fish_helpers import (
    add_swim,
    body_length,
    evaluated,
    frames,
    live,
    make_fish,
    rest,
    set_fps,
)


def _keyframe_frequency(obj, values):
    settings = obj.kodawari_swim
    for frame, value in values:
        settings.frequency = value
        obj.keyframe_insert("kodawari_swim.frequency", frame=frame)
    from kodawari import fcurves

    curve = fcurves.find_fcurve(obj.animation_data.action, obj, "kodawari_swim.frequency")
    for point in curve.keyframe_points:
        point.interpolation = "CONSTANT"


def test_changing_frequency_mid_animation_leaves_no_jump(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=1.0)
    _keyframe_frequency(obj, [(1, 1.0), (21, 3.0)])  # a sudden step at frame 21
    positions = frames(obj, range(1, 41))
    steps = np.linalg.norm(np.diff(positions, axis=0), axis=2).max(
        axis=1
    )  # largest vertex move per frame
    # At 3 Hz the fastest steady step is ~3x the 1 Hz one; the frame of the change must not exceed it
    # (ω·t would shift the whole wave by 2π·2 Hz·20/24 s in one frame).
    steady_fast = steps[25:].max()
    assert steps[19] <= 1.05 * steady_fast, (steps[17:23], steady_fast)
    assert steps[:18].max() < 0.5 * steady_fast  # the frequency did change


@pytest.mark.parametrize("target", ["MESH_CACHE", "SHAPE_KEYS"])
def test_bake_equals_live(empty_scene, tmp_path, target):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(
        obj,
        fins=("fin_pectoral", "fin_dorsal"),
        head_axis="POS_X",
        preset="CARANGIFORM",
        frequency=2.0,
    )
    live_frames = frames(obj, range(1, 13))
    cache = str(tmp_path / "tuna.pc2")
    assert bpy.ops.kodawari.swim_bake(
        frame_start=1, frame_end=12, target=target, filepath=cache
    ) == {"FINISHED"}
    assert (
        obj.kodawari_swim.baked == target and not obj.kodawari_swim.enabled
    ) or obj.kodawari_swim.baked == target
    if target == "MESH_CACHE":
        assert os.path.isfile(cache)
        assert obj.modifiers[0].type == "MESH_CACHE"
    scene = bpy.context.scene
    for index, frame in enumerate(range(1, 13)):
        scene.frame_set(frame)
        assert np.abs(evaluated(obj) - live_frames[index]).max() < 1e-5, frame


def test_pc2_file_layout(empty_scene, tmp_path):
    set_fps(24)
    obj = make_fish("eel")
    add_swim(obj, head_axis="POS_X", preset="ANGUILLIFORM")
    live_frames = frames(obj, range(5, 9))
    cache = str(tmp_path / "eel.pc2")
    bpy.ops.kodawari.swim_bake(frame_start=5, frame_end=8, target="MESH_CACHE", filepath=cache)
    with open(cache, "rb") as handle:
        header = handle.read(32)
        data = np.frombuffer(handle.read(), dtype="<f4")
    assert header[:12] == b"POINTCACHE2\0"
    version, points, start, rate, samples = np.frombuffer(
        header[12:], dtype=[("v", "<i4"), ("n", "<i4"), ("s", "<f4"), ("r", "<f4"), ("k", "<i4")]
    )[0]
    assert (version, points, start, rate, samples) == (1, len(obj.data.vertices), 5.0, 1.0, 4)
    # The bake computes in the core what the Fish Swim modifier computes in Blender's nodes
    # (docs/algorithms.md §1.6): the same shape up to float rounding.
    assert np.abs(data.reshape(4, points, 3) - live_frames).max() < 1e-5 * body_length(obj)


def test_settings_survive_save_and_reload(empty_scene, tmp_path):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral",), head_axis="POS_X", preset="THUNNIFORM", frequency=2.5)
    settings = obj.kodawari_swim
    settings.amplitude = 0.11
    settings.wavelength = 1.3
    settings.bend = "DORSOVENTRAL"
    settings.speed_mode = "STROUHAL"
    settings.strouhal = 0.27
    settings.fins[0].feathering = 0.5
    settings.fins[0].phase_lag = 1.1
    bpy.context.scene.frame_set(7)
    before = live(obj).copy()
    path = str(tmp_path / "fish.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    bpy.ops.wm.open_mainfile(filepath=path)
    obj = bpy.data.objects["tuna"]
    settings = obj.kodawari_swim
    assert settings.enabled and settings.preset == "THUNNIFORM" and settings.bend == "DORSOVENTRAL"
    assert settings.amplitude == pytest.approx(0.11) and settings.wavelength == pytest.approx(1.3)
    assert settings.speed_mode == "STROUHAL" and settings.strouhal == pytest.approx(0.27)
    assert settings.fins[0].vertex_group == "fin_pectoral"
    assert settings.fins[0].feathering == pytest.approx(0.5) and settings.fins[
        0
    ].phase_lag == pytest.approx(1.1)
    # The runtime is rebuilt from the file: the same frame gives the same pose.
    bpy.context.scene.frame_set(3)
    bpy.context.scene.frame_set(7)
    assert np.abs(live(obj) - before).max() < 1e-6


def test_undo_after_swim_add_restores_the_mesh(empty_scene):
    obj = make_fish("tuna")
    original = rest(obj).copy()
    assert "UNDO" in bpy.types.KODAWARI_OT_swim_add.bl_options
    bpy.ops.ed.undo_push(message="before swim")
    add_swim(obj, head_axis="AUTO")
    assert bpy.data.objects["tuna"].modifiers.get("Fish Swim") is not None
    # With a window, Blender pushes this step itself after an UNDO operator; headless, the test does.
    bpy.ops.ed.undo_push(message="Add Fish Swim")
    bpy.ops.ed.undo()
    obj = bpy.data.objects["tuna"]
    assert obj.data.shape_keys is None and len(obj.modifiers) == 0
    assert not [a.name for a in obj.data.attributes if "kodawari" in a.name]
    assert not obj.kodawari_swim.enabled
    assert np.array_equal(rest(obj), original)
    bpy.context.scene.frame_set(5)  # the handler copes with the undone object


def test_swim_remove_restores_the_original_mesh_exactly(empty_scene, tmp_path):
    set_fps(24)
    obj = make_fish("dolphin")
    original = rest(obj).copy()
    groups = [g.name for g in obj.vertex_groups]
    add_swim(obj, fins=("fin_pectoral",), head_axis="POS_X", preset="CETACEAN")
    obj.kodawari_swim.speed_mode = "BAINBRIDGE"
    bpy.context.scene.frame_set(9)
    bpy.ops.kodawari.swim_bake(
        frame_start=1, frame_end=5, target="MESH_CACHE", filepath=str(tmp_path / "d.pc2")
    )
    assert bpy.ops.kodawari.swim_remove() == {"FINISHED"}
    assert obj.data.shape_keys is None and len(obj.modifiers) == 0
    assert tuple(obj.delta_location) == (0.0, 0.0, 0.0)
    assert not obj.kodawari_swim.enabled and len(obj.kodawari_swim.fins) == 0
    assert [g.name for g in obj.vertex_groups] == groups
    bpy.context.scene.frame_set(3)
    assert np.array_equal(rest(obj), original)
    assert np.array_equal(evaluated(obj), original)


def test_auto_head_axis_guesses_reports_and_flips(empty_scene):
    obj = make_fish("tuna", head_axis="NEG_Y")
    settings = add_swim(obj, head_axis="AUTO")
    assert settings.head_axis == "NEG_Y"
    assert "-Y" in settings.head_guess
    # The live handler writes the shape key on frame changes, so renders must lock the interface.
    assert empty_scene.render.use_lock_interface
    assert bpy.ops.kodawari.swim_flip_head() == {"FINISHED"}
    assert settings.head_axis == "POS_Y"


def test_axis_follows_a_curved_midline(empty_scene):
    obj = make_fish("eel", midline_sag=0.08)
    add_swim(obj, head_axis="POS_X")
    from kodawari.fish import runtime

    axis = runtime.get_rig(obj).axis_rest
    # The middle control point sits low, with the sagging body, not on a straight line.
    middle = axis[len(axis) // 2]
    assert middle[2] < -0.05, axis


def test_bainbridge_speed_moves_the_fish_forward(empty_scene):
    set_fps(24)
    obj = make_fish("tuna", head_axis="NEG_Y")
    settings = add_swim(obj, head_axis="NEG_Y", preset="CARANGIFORM", frequency=3.0)
    settings.speed_mode = "BAINBRIDGE"
    scene = bpy.context.scene
    scene.frame_set(25)  # one second after the start frame
    length = body_length(obj, axis=1)
    expected = 0.25 * length * (3 * 3.0 - 4)  # Bainbridge (1958): V = L (3f - 4) / 4
    moved = np.array(obj.delta_location)
    assert moved[1] == pytest.approx(-expected, rel=0.02)  # along the head (-Y)
    assert abs(moved[0]) < 1e-6 and abs(moved[2]) < 1e-6


def test_swim_follows_a_path_curve(empty_scene):
    set_fps(24)
    bpy.ops.curve.primitive_bezier_circle_add(radius=4.0)
    path = bpy.context.active_object
    obj = make_fish("tuna")
    settings = add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=3.0)
    follow = obj.constraints.new("FOLLOW_PATH")
    follow.target = path
    settings.speed_mode = "STROUHAL"
    scene = bpy.context.scene
    scene.frame_set(1)
    start = follow.offset_factor
    scene.frame_set(25)
    assert follow.offset_factor > start
    circumference = 2 * np.pi * 4.0
    expected = 3.0 * 2 * settings.amplitude * body_length(obj) / settings.strouhal  # U = f A / St
    assert (follow.offset_factor - start) * circumference == pytest.approx(expected, rel=0.03)


def test_fin_finder_makes_vertex_groups_and_fins(empty_scene):
    obj = make_fish("tuna")
    truth = {g.name: set() for g in obj.vertex_groups}
    for v in obj.data.vertices:
        for g in v.groups:
            truth[obj.vertex_groups[g.group].name].add(v.index)
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    add_swim(obj, head_axis="POS_X")
    assert bpy.ops.kodawari.swim_fin_find() == {"FINISHED"}
    found = {
        g.name: {v.index for v in obj.data.vertices for e in v.groups if e.group == g.index}
        for g in obj.vertex_groups
    }
    for name in ("fin_dorsal", "fin_pectoral", "fin_caudal"):
        assert name in found, found.keys()
        overlap = len(found[name] & truth[name]) / len(found[name] | truth[name])
        assert overlap > 0.5, (name, overlap)
    assert {f.kind for f in obj.kodawari_swim.fins} >= {"DORSAL", "PECTORAL", "CAUDAL"}


def test_shape_key_memory_write_matches_what_blender_reads(empty_scene):
    from kodawari import bulk

    obj = make_fish("tuna")
    obj.shape_key_add(name="Basis", from_mix=False)
    block = obj.shape_key_add(name="Swim", from_mix=False)
    block.value = 1.0
    positions = rest(obj) + np.random.default_rng(1).normal(size=rest(obj).shape).astype(np.float32)
    # The raw memory path is taken exactly where RNA lacks a fast one (before 4.1).
    assert bulk.write_shape_key_positions(block, positions) == (bpy.app.version < (4, 1, 0))
    assert np.array_equal(bulk.shape_key_positions(block), positions)
    assert np.abs(evaluated(obj) - positions).max() < 1e-6


def test_spine_bends_into_the_turns_of_a_path(empty_scene):
    set_fps(24)
    bpy.ops.curve.primitive_bezier_circle_add(radius=2.0)
    circle = bpy.context.active_object
    obj = make_fish("eel")
    settings = add_swim(obj, head_axis="POS_X", preset="ANGUILLIFORM", frequency=3.0)
    settings.amplitude = settings.amplitude_head = 0.0  # no wave: only the path's bend
    settings.path_start = 0.25
    follow = obj.constraints.new("FOLLOW_PATH")
    follow.target = circle
    settings.speed_mode = "BAINBRIDGE"
    bpy.context.scene.frame_set(12)
    from kodawari.fish import runtime

    axis = runtime.get_rig(obj).axis
    middle = axis[len(axis) // 2]
    # Head and tail bend toward the circle's centre by the sagitta d² / 2R (R = 2).
    to_centre = np.array(obj.matrix_world.inverted() @ circle.matrix_world.translation) - middle
    to_centre[0] = 0.0
    to_centre /= np.linalg.norm(to_centre)
    for end in (axis[0], axis[-1]):
        d = abs(end[0] - middle[0])
        assert (end - middle) @ to_centre == pytest.approx(d**2 / (2 * 2.0), rel=0.2)
    # The whole fish lies along the circle.
    world = np.array(obj.matrix_world)
    positions = evaluated(obj) @ world[:3, :3].T + world[:3, 3]
    radii = np.linalg.norm(positions[:, :2] - np.array(circle.location[:2]), axis=1)
    assert np.abs(radii - 2.0).max() < 0.1


def test_user_shape_keys_added_later_apply_on_top(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X")
    bpy.context.scene.frame_set(4)
    swim = live(obj).copy()
    smile = obj.shape_key_add(name="Smile", from_mix=False)
    offsets = np.zeros_like(swim)
    offsets[:, 2] = 0.01
    smile.data.foreach_set("co", (rest(obj) + offsets).reshape(-1))
    smile.value = 1.0
    bpy.context.scene.frame_set(4)
    assert np.abs(evaluated(obj) - (swim + offsets)).max() < 1e-5


def test_axis_overlay_follows_the_swimming_axis(empty_scene):
    from kodawari.fish import overlay

    obj = make_fish("eel")
    obj.location = (1.0, 2.0, 3.0)
    add_swim(obj, head_axis="POS_X", preset="ANGUILLIFORM")
    bpy.context.scene.frame_set(5)
    curve, points = overlay.axis_polylines(obj)
    assert points.shape == (16, 3) and curve.shape == (overlay.CURVE_SAMPLES, 3)
    assert np.allclose(curve[0], points[0]) and np.allclose(curve[-1], points[-1])  # clamped ends
    assert np.allclose(points.mean(axis=0)[:2], (1.0, 2.0), atol=0.1)  # in world space
    obj.kodawari_swim.show_axis = False
    assert overlay.axis_polylines(obj) is None


def test_bake_without_frames_uses_the_scene_range_and_speed_off_returns_home(empty_scene, tmp_path):
    set_fps(24)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 3, 9
    obj = make_fish("tuna")
    settings = add_swim(obj, head_axis="POS_X", frequency=3.0)
    settings.speed_mode = "BAINBRIDGE"
    scene.frame_set(9)
    assert obj.delta_location[0] > 0.1
    settings.speed_mode = "NONE"
    assert tuple(obj.delta_location) == (0.0, 0.0, 0.0)
    cache = tmp_path / "t.pc2"
    assert bpy.ops.kodawari.swim_bake(filepath=str(cache)) == {"FINISHED"}
    from kodawari.fish import bake

    start, _, data = bake.read_pc2(str(cache))
    assert start == 3.0 and data.shape[0] == 7
