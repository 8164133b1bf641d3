"""Edits to a swimming mesh are followed, not silently undone (issue 10 items 3, 4)."""

import bpy  # first: puts Blender's own modules on sys.path

# isort: split
import bmesh
import numpy as np
from fish_helpers import activate, add_swim, live, make_fish, rest, set_fps


def _length(points):
    return float(np.ptp(points[:, 0]))


def test_apply_scale_is_followed_on_the_next_frame(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    scene = bpy.context.scene
    scene.frame_set(2)
    before = _length(live(obj))
    obj.scale = (2.0, 2.0, 2.0)
    activate(obj)
    bpy.ops.object.transform_apply(location=False, rotation=False, scale=True)
    scene.frame_set(3)
    assert abs(_length(live(obj)) / before - 2.0) < 0.02, (_length(live(obj)), before)


def test_edit_mode_moves_are_followed_on_the_next_frame(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    scene = bpy.context.scene
    scene.frame_set(2)
    activate(obj)
    bpy.ops.object.mode_set(mode="EDIT")
    bm = bmesh.from_edit_mesh(obj.data)
    lifted = [v.index for v in bm.verts if v.co.x > 0.3]  # the head
    for v in bm.verts:
        if v.co.x > 0.3:
            v.co.z += 0.2
    bmesh.update_edit_mesh(obj.data)
    bpy.ops.object.mode_set(mode="OBJECT")
    scene.frame_set(3)
    # The head swims where it was moved to (its own swim motion is small).
    rise = live(obj)[lifted, 2] - rest(obj)[lifted, 2]
    assert np.abs(rise).max() < 0.05, np.abs(rise).max()
    assert (live(obj)[lifted, 2].mean() - 0.2) > -0.05


def test_linked_duplicates_swim_with_their_own_settings(empty_scene):
    set_fps(24)
    obj = make_fish("tuna")
    add_swim(obj, head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    activate(obj)
    bpy.ops.object.duplicate(linked=True)
    twin = bpy.context.active_object
    assert twin is not obj and twin.data is obj.data
    twin.kodawari_swim.frequency = 1.0
    scene = bpy.context.scene
    tail = int(np.argmin(rest(obj)[:, 0]))
    sideways = {o.name: [] for o in (obj, twin)}
    for frame in range(1, 25):
        scene.frame_set(frame)
        for o in (obj, twin):
            sideways[o.name].append(float(live(o)[tail, 1]))
    a, b = (np.array(sideways[o.name]) for o in (obj, twin))
    # Each beats at its own frequency: 2 Hz repeats after 12 frames, 1 Hz does not.
    assert np.abs(a[12:] - a[:12]).max() < 1e-4
    assert np.abs(b[12:] - b[:12]).max() > 0.01
    assert twin.data is not obj.data
