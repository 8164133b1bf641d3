"""One broken creature never stops the others (issue 11 items 8, 9): its failure is said
once (console, report area via the problem operator, its panel status) instead of a
traceback on every frame, the other creatures keep moving, and a bake of it fails
cleanly with everything put back."""

import itertools

import bpy
import numpy as np
import pytest
from bake_scenes import hair_rig, swimming_fish
from fish_helpers import activate, live


def _two_fish():
    return swimming_fish("a_broken", fins=("fin_dorsal",)), swimming_fish("b_healthy")


def _empty_path(fish):
    curve = bpy.data.curves.new("empty_path", "CURVE")
    path = bpy.data.objects.new("empty_path", curve)
    bpy.context.scene.collection.objects.link(path)
    follow = fish.constraints.new("FOLLOW_PATH")
    follow.target = path
    fish.kodawari_swim.speed_mode = "STROUHAL"
    return path


@pytest.mark.parametrize("breakage", ["deleted_group", "renamed_group", "empty_path"])
def test_a_broken_fish_is_reported_once_and_the_others_keep_swimming(empty_scene, capfd, breakage):
    broken, healthy = _two_fish()
    capfd.readouterr()
    if breakage == "deleted_group":
        broken.vertex_groups.remove(broken.vertex_groups["fin_dorsal"])
        words = ["fin_dorsal", "missing"]
    elif breakage == "renamed_group":
        broken.vertex_groups["fin_dorsal"].name = "Dorsal"
        words = ["fin_dorsal", "missing"]
    else:
        _empty_path(broken)
        words = ["empty_path", "no points"]
    from kodawari.fish import runtime

    runtime.forget()  # rigs are rebuilt from the file's data (as after undo or reopening)
    shapes = []
    for frame in range(2, 8):
        empty_scene.frame_set(frame)
        shapes.append(live(healthy).copy())
    assert (
        min(np.abs(a - b).max() for a, b in itertools.pairwise(shapes)) > 1e-4
    )  # still swims every frame
    out, err = capfd.readouterr()
    said = [line for line in (out + err).splitlines() if "a_broken" in line]
    assert len(said) == 1, out + err  # once, not once per frame
    assert "Traceback" not in out + err
    from kodawari import problems

    status = problems.message(broken, "swim")
    for word in words:
        assert word in status and word in said[0], (status, said)
    assert problems.message(healthy, "swim") == ""
    # Its bake is refused in words before anything changes; the healthy fish still bakes.
    activate(broken)
    with pytest.raises(RuntimeError) as info:
        bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=4, target="SHAPE_KEYS")
    assert "Traceback" not in str(info.value) and broken.kodawari_swim.baked == "NONE", info.value
    assert words[0] in str(info.value), info.value
    activate(healthy)
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=4, target="SHAPE_KEYS") == {
        "FINISHED"
    }


def test_a_broken_fish_does_not_stop_a_file_from_opening(empty_scene, tmp_path, capfd):
    broken, healthy = _two_fish()
    broken.vertex_groups.remove(broken.vertex_groups["fin_dorsal"])
    path = str(tmp_path / "broken.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    capfd.readouterr()
    bpy.ops.wm.open_mainfile(filepath=path)
    out, err = capfd.readouterr()
    assert "Traceback" not in out + err, out + err
    from kodawari import problems

    assert "fin_dorsal" in problems.message(bpy.data.objects["a_broken"], "swim")
    healthy = bpy.data.objects["b_healthy"]
    before = live(healthy).copy()
    bpy.context.scene.frame_set(5)
    assert np.abs(live(healthy) - before).max() > 1e-4


def test_a_hair_bake_on_a_frame_that_cannot_be_simulated_fails_cleanly(empty_scene):
    """Item 9: armature scale 0 -> a clear message; frame, live switch, action and pose as they were."""
    rig = hair_rig(empty_scene)
    rig.kodawari_hair.enabled = False
    empty_scene.frame_set(9)
    rig.scale = (0.0, 0.0, 0.0)
    rotations = [tuple(pb.rotation_quaternion) for pb in rig.pose.bones]
    with pytest.raises(RuntimeError) as info:
        bpy.ops.kodawari.rod_bake(frame_start=1, frame_end=20)
    message = str(info.value)
    assert "Hair bake failed and was undone" in message, message
    assert "Traceback" not in message and "IndexError" not in message, message
    assert empty_scene.frame_current == 9
    assert not rig.kodawari_hair.enabled
    assert rig.animation_data is None or rig.animation_data.action is None
    assert [tuple(pb.rotation_quaternion) for pb in rig.pose.bones] == rotations
