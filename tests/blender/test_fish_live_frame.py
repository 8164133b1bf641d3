"""The live frame: what Blender shows follows every write, and the wave phase at a late
frame is the same running sum whether reached by playing, jumping or after a key change
(issue 12 item 3, issue 13 items 1 and 3)."""

import math

import bpy
import numpy as np
from fish_helpers import add_swim, evaluated, live, make_fish, set_fps


def test_evaluated_mesh_follows_each_frame_write(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    for frame in (2, 3, 4, 9):
        bpy.context.scene.frame_set(frame)
        assert np.abs(evaluated(obj) - live(obj)).max() < 1e-6, frame


def _phase(obj, frame):
    from kodawari.fish import runtime, timing

    rig = runtime.get_rig(obj)
    return timing.phase_and_distance(
        obj, obj.kodawari_swim, bpy.context.scene, frame, rig.body_length
    )


def test_late_frame_phase_is_the_running_sum_and_follows_key_edits(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    settings = add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    settings.speed_mode = "STROUHAL"
    settings.frequency = 1.0
    settings.keyframe_insert("frequency", frame=1)
    settings.frequency = 3.0
    settings.keyframe_insert("frequency", frame=500)

    def expected(frame):
        from kodawari import fcurves

        fc = fcurves.find_fcurve(obj.animation_data.action, obj, "kodawari_swim.frequency")
        frames = np.arange(1, frame + 1, dtype=float)
        f = np.array([fc.evaluate(x) for x in frames])
        return 2 * math.pi * float(np.sum(0.5 * (f[1:] + f[:-1])) / 24.0)

    late, _ = _phase(obj, 3000)  # jumped to directly
    assert abs(late - expected(3000)) < 1e-6 * late
    played = [_phase(obj, frame)[0] for frame in range(2990, 3001)]  # then played
    assert abs(played[-1] - late) < 1e-9
    half, _ = _phase(obj, 2500.5)  # a subframe
    assert _phase(obj, 2500)[0] < half < _phase(obj, 2501)[0]
    # Editing a key changes every later phase at once.
    from kodawari import fcurves

    fc = fcurves.find_fcurve(obj.animation_data.action, obj, "kodawari_swim.frequency")
    fc.keyframe_points[1].co.y = 4.0
    fc.update()
    edited, _ = _phase(obj, 3000)
    assert abs(edited - expected(3000)) < 1e-6 * edited
    assert edited > late
