"""Runtime caches are keyed so that renaming an object keeps its state
(CONTRIBUTING.md, "Runtime caches"): a hair simulation carries on through a rename
instead of restarting, and the last gait bake stays attached to its rig."""

import bpy
import numpy as np
from hair_rig import make_rig, rotations, run_frames, select_only


def _hair(scene, name):
    obj = make_rig(scene)
    obj.name = name
    chain = obj.pose.bones[2].name.split(".")[0]
    select_only(obj, {f"{chain}.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    obj.kodawari_hair.rods[0].wind = (4.0, 0.0, 0.0)  # gusty side wind: the chain keeps moving
    return obj, chain


def test_renaming_a_simulating_armature_does_not_restart_its_hair(empty_scene):
    from kodawari.hair import runtime

    empty_scene.frame_start, empty_scene.frame_end = 1, 250
    kept, chain = _hair(empty_scene, "Kept")
    renamed, _ = _hair(empty_scene, "Renamed")
    run_frames(empty_scene, 1, 6)
    before = runtime.get(renamed)
    renamed.name = "Renamed Later"
    run_frames(empty_scene, 7, 14)
    assert runtime.get(renamed) is before
    # The renamed twin moves exactly as the one left alone: nothing restarted.
    moved = rotations(kept, chain)
    assert np.abs(moved - [1.0, 0.0, 0.0, 0.0]).max() > 0.05  # it really is swinging
    assert np.array_equal(rotations(renamed, chain), moved)


def test_the_last_gait_bake_stays_with_a_renamed_rig(empty_scene):
    from gait_scene import horse
    from kodawari.gait import runtime

    rig = horse(empty_scene, [(1, 2.0), (20, 2.0)])
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=20) == {"FINISHED"}
    solved = runtime.last_bake(rig)
    rig.name = "Renamed Horse"
    assert runtime.last_bake(rig) is solved
