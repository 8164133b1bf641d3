"""fcurves.py writes keys in bulk on every Blender, slotted actions (4.4+) included."""

import bpy
import numpy as np


def test_write_channels_round_trips_through_evaluation(empty_scene):
    from kodawari import fcurves

    obj = bpy.data.objects.new("Empty", None)
    empty_scene.collection.objects.link(obj)
    action = fcurves.ensure_action(obj, "Test")
    frames = np.arange(1, 101, dtype=np.float32)
    values = np.stack([np.sin(frames / 10), np.cos(frames / 10), frames / 100], axis=1)
    curves = fcurves.write_channels(action, obj, "location", frames, values, group="Object")
    assert len(curves) == 3
    assert len(fcurves.action_fcurves(action, obj)) == 3
    for frame in (1, 37, 100):
        empty_scene.frame_set(frame)
        np.testing.assert_allclose(obj.location, values[frame - 1], atol=1e-6)
    # Writing again replaces the curves rather than adding more.
    fcurves.write_channels(action, obj, "location", frames, values * 2)
    assert len(fcurves.action_fcurves(action, obj)) == 3
    empty_scene.frame_set(50)
    np.testing.assert_allclose(obj.location, values[49] * 2, atol=1e-6)
