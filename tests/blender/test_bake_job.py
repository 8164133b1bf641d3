"""One bake lifecycle for the fish, gait and hair bakes (issue 12 item 1): the same frame
range rule, and a failure in the middle of any bake is undone and reported in words,
never a traceback, with nothing left half-written. Headless, the bakes run to the end."""

import os

import bpy
import numpy as np
import pytest
from bake_scenes import hair_rig, swimming_fish
from fish_helpers import activate
from gait_scene import fcurve_snapshot, horse

HEAD_KEYS = ((1, 0.0), (8, 0.3), (16, -0.2))


def _fish(tmp_path):
    return swimming_fish(fins=("fin_dorsal",))


def _hair(scene):
    return hair_rig(scene, HEAD_KEYS)


def _key_range(obj, prefix):
    from kodawari import fcurves

    frames = [
        fcurves.read_keys(c)[0]
        for c in fcurves.action_fcurves(obj.animation_data.action, obj)
        if c.data_path.startswith(prefix)
    ]
    assert frames, prefix
    return int(min(f.min() for f in frames)), int(max(f.max() for f in frames))


def test_every_bake_uses_the_scene_range_when_frames_are_unset(empty_scene, tmp_path):
    """The one frame-range rule: operators called without frames bake the scene's range."""
    from kodawari.fish import bake

    scene = empty_scene
    fish = _fish(tmp_path)
    rig = _hair(scene)
    gait = horse(scene, [(1, 2.0), (40, 2.0)])
    scene.frame_start, scene.frame_end = 3, 17
    activate(fish)
    cache = str(tmp_path / "fish.pc2")
    assert bpy.ops.kodawari.swim_bake(target="MESH_CACHE", filepath=cache) == {"FINISHED"}
    start, _, data = bake.read_pc2(cache)
    assert (start, len(data)) == (3.0, 15)
    bpy.context.view_layer.objects.active = gait
    assert bpy.ops.kodawari.gait_bake() == {"FINISHED"}
    assert _key_range(gait, 'pose.bones["body"]') == (3, 17)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.rod_bake() == {"FINISHED"}
    assert _key_range(rig, 'pose.bones["Ahoge') == (3, 17)


def test_every_bake_operator_shares_the_base():
    from kodawari.bake_job import BakeOperator

    for name in ("swim_bake", "gait_bake", "rod_bake"):
        cls = getattr(bpy.types, f"KODAWARI_OT_{name}")
        assert issubclass(cls, BakeOperator), name


def _fails_on_the_third_call(monkeypatch, module, name):
    original = getattr(module, name)
    calls = {"n": 0}

    def failing(*args, **kwargs):
        calls["n"] += 1
        if calls["n"] == 3:
            raise RuntimeError("simulated failure in the middle of the bake")
        return original(*args, **kwargs)

    monkeypatch.setattr(module, name, failing)
    return calls


def _refused_cleanly(operator, **kwargs):
    with pytest.raises(RuntimeError) as info:
        operator(**kwargs)
    message = str(info.value)
    assert "failed and was undone" in message and "simulated failure" in message, message
    assert "Traceback" not in message, message


def test_a_fish_bake_failing_midway_is_undone(empty_scene, tmp_path, monkeypatch):
    from kodawari.fish import runtime

    obj = _fish(tmp_path)
    empty_scene.frame_set(5)
    modifiers = [m.name for m in obj.modifiers]
    calls = _fails_on_the_third_call(monkeypatch, runtime, "positions")
    _refused_cleanly(
        bpy.ops.kodawari.swim_bake, frame_start=1, frame_end=20, filepath=str(tmp_path / "f.pc2")
    )
    assert calls["n"] >= 3  # the third frame failed (restoring the frame evaluates once more)
    assert os.listdir(tmp_path) == []  # no cache, no .part
    assert [m.name for m in obj.modifiers] == modifiers and obj.kodawari_swim.baked == "NONE"
    assert empty_scene.frame_current == 5


def test_a_gait_bake_failing_midway_is_undone(empty_scene, monkeypatch):
    from kodawari import fcurves

    rig = horse(empty_scene, [(1, 2.0), (40, 2.0)])
    action = rig.animation_data.action
    before = fcurve_snapshot(rig)
    modes = {pb.name: pb.rotation_mode for pb in rig.pose.bones}
    _fails_on_the_third_call(monkeypatch, fcurves, "write_channels")
    _refused_cleanly(bpy.ops.kodawari.gait_bake, frame_start=1, frame_end=40)
    assert rig.animation_data.action == action
    assert fcurve_snapshot(rig) == before
    assert {pb.name: pb.rotation_mode for pb in rig.pose.bones} == modes
    assert not [k for k in rig.keys() if k.startswith("kodawari_contact")]


def test_a_hair_bake_failing_midway_is_undone_and_not_simulated_by_the_live_handler(
    empty_scene, monkeypatch
):
    from kodawari.hair import runtime

    rig = _hair(empty_scene)
    empty_scene.frame_set(6)
    rotations = np.array([tuple(pb.rotation_quaternion) for pb in rig.pose.bones])
    action = rig.animation_data.action
    before = fcurve_snapshot(rig)
    live = []
    hair_armatures = runtime.hair_armatures
    monkeypatch.setattr(
        runtime,
        "evaluate_scene",
        lambda scene, *_: live.append(
            (scene.frame_current, [o.name for o in hair_armatures(scene)])
        ),
    )
    _fails_on_the_third_call(monkeypatch, runtime.ArmatureRuntime, "evaluate")
    _refused_cleanly(bpy.ops.kodawari.rod_bake, frame_start=1, frame_end=30)
    assert empty_scene.frame_current == 6 and rig.kodawari_hair.enabled
    assert rig.animation_data.action == action and fcurve_snapshot(rig) == before
    assert np.allclose([tuple(pb.rotation_quaternion) for pb in rig.pose.bones], rotations)
    # The bake simulated with its own runtime: the live handler simulated the rig only once
    # it was switched back on (restoring the current frame), never on the baked frames.
    assert [frame for frame, names in live if rig.name in names] == [6], live
    assert [frame for frame, _ in live][:3] == [1, 2, 3], live
