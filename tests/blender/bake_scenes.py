"""Creatures the bake and hardening tests build: a swimming fish, a hair rig with a rod."""

import bpy
from fish_helpers import add_swim, make_fish, set_fps
from hair_rig import add_camera, make_rig, select_only


def swimming_fish(name="tuna", fins=(), **swim):
    """A procedural tuna called `name`, swimming (24 fps, head along +X)."""
    set_fps(24)
    obj = make_fish("tuna")
    obj.name = name
    add_swim(obj, fins=fins, head_axis="POS_X", **swim)
    return obj


def hair_rig(scene, head_keys=()):
    """The small character rig with one rod (Ahoge), a front camera, and the head keyed at
    (frame, x) pairs so the hair swings; in Object Mode."""
    rig = make_rig(scene)
    select_only(rig, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    add_camera(scene, "Front", (0, -4, 1.7))
    head = rig.pose.bones["Head"]
    for frame, x in head_keys:
        head.location = (x, 0.0, 0.0)
        head.keyframe_insert("location", frame=frame)
    return rig
