"""kodawari.gait_report measures the baked Action: the seed's smoothness criteria per
gait segment (JSON) and the footfall + fore-aft trajectory PNG; it equals the bake."""

import json
import os

import bpy
import numpy as np
import pytest
from gait_scene import horse

RAMP = [(1, 1.5), (48, 1.5), (360, 17.0), (672, 1.5), (720, 1.5)]


def test_ramp_through_every_gait_is_smooth_and_the_report_equals_the_bake(empty_scene, tmp_path):
    from kodawari.gait import runtime

    rig = horse(empty_scene, RAMP)
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=720) == {"FINISHED"}
    out = str(tmp_path / "gait_report.png")
    assert bpy.ops.kodawari.gait_report(filepath=out) == {"FINISHED"}
    report = json.load(open(str(tmp_path / "gait_report.json")))
    segs = report["segments"]
    assert [s["gait"] for s in segs] == [
        "WALK",
        "TROT",
        "CANTER",
        "GALLOP",
        "CANTER",
        "TROT",
        "WALK",
    ]
    for s in segs:
        assert s["largest_stance_slide"] < 0.005, s["gait"]  # planted feet hold (< 5 mm)
        assert s["largest_swing_jump_ratio"] < 2.5, s["gait"]  # a swinging foot never jumps
        assert s["joint_limit_violations"] == 0
        for leg, entry in s["legs"].items():
            assert entry["largest_foot_root_distance"] <= entry["reach"] + 0.005, (s["gait"], leg)
    # The report measured the Action; the bake remembered what it solved: the same motion.
    from kodawari.gait.report import measure_baked

    solved = runtime.last_bake(rig)["result"]
    measured = measure_baked(rig, 24)
    assert np.array_equal(measured["contacts"], solved["contacts"])
    assert np.array_equal(measured["gait"], solved["gait"])
    assert np.abs(measured["feet"] - solved["feet"]).max() < 1e-3  # float32 F-curves
    # The picture: footfall rows and trajectories drawn, saved as PNG.
    image = bpy.data.images.load(out)
    assert image.size[0] == 1400 and image.size[1] > 400
    pixels = np.empty(image.size[0] * image.size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    dark = (pixels.reshape(-1, 4)[:, :3].sum(axis=1) < 0.6).mean()
    assert 0.02 < dark < 0.5  # planted bars and text, not a blank or black page


def test_report_without_a_bake_is_refused(empty_scene, tmp_path):
    horse(empty_scene)
    out = str(tmp_path / "r.png")
    with pytest.raises(RuntimeError, match="bake the gait first"):
        bpy.ops.kodawari.gait_report(filepath=out)
    assert not os.path.exists(out)


def test_loading_a_file_rebuilds_runtime_state(empty_scene, tmp_path):
    from kodawari.gait import runtime

    rig = horse(empty_scene, [(1, 2.0), (30, 2.0)])
    bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=30)
    assert runtime.last_bake(rig) is not None
    path = str(tmp_path / "horse.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    bpy.ops.wm.open_mainfile(filepath=path)
    rig = bpy.data.objects["Horse"]
    assert runtime.last_bake(rig) is None  # stale solver memory dropped...
    assert (
        rig.kodawari_gait.legs["LF"].bones[0].name == "fore_scapula.L"
    )  # ...settings saved with the file
    out = str(tmp_path / "again.png")
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.gait_report(filepath=out) == {
        "FINISHED"
    }  # measured from the saved Action


def test_report_measures_what_blender_shows_not_the_keys(empty_scene, tmp_path):
    """A constraint that holds the body back (another action, a rig's own constraint):
    the keys are unchanged, but in Blender the planted feet are dragged along. The report
    measures the evaluated pose, so it shows the slide."""
    rig = horse(empty_scene, [(1, 2.0), (72, 2.0)])
    for child in list(rig.children):
        bpy.data.objects.remove(child)
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=72) == {"FINISHED"}
    out = str(tmp_path / "r.png")
    assert bpy.ops.kodawari.gait_report(filepath=out) == {"FINISHED"}
    clean = json.load(open(str(tmp_path / "r.json")))["segments"]
    assert max(s["largest_stance_slide"] for s in clean) < 0.005
    limit = rig.pose.bones["body"].constraints.new("LIMIT_LOCATION")
    limit.use_min_y = limit.use_max_y = True
    limit.min_y = limit.max_y = 0.0  # the body stays put; the legs still step
    limit.owner_space = "LOCAL"
    assert bpy.ops.kodawari.gait_report(filepath=out) == {"FINISHED"}
    held = json.load(open(str(tmp_path / "r.json")))["segments"]
    assert max(s["largest_stance_slide"] for s in held) > 0.05
