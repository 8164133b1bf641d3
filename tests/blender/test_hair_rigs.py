"""Hair on rigs shaped like real characters (issue 9 items 2 and 6): VRM-style hair whose
bones are not connected to their parents (a gap between parent tail and child head) and
carry arbitrary rolls; renamed bones."""

import math

import bpy
import numpy as np
from hair_rig import add_camera, angle_deg, select_only
from mathutils import Vector


def make_vrm_like_rig(scene, bones=16, gap=0.012, seed=3):
    """Head with a hanging side lock: every bone unconnected (a gap after its parent's tail),
    rolled arbitrarily, bent a little in the rest pose, as VRM exporters leave hair."""
    rng = np.random.default_rng(seed)
    data = bpy.data.armatures.new("VrmRig")
    obj = bpy.data.objects.new("VrmRig", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    root = data.edit_bones.new("J_Bip_C_Hips")
    root.head, root.tail = (0, 0, 0.9), (0, 0, 1.0)
    head = data.edit_bones.new("J_Bip_C_Head")
    head.head, head.tail = (0, 0, 1.45), (0, 0, 1.6)
    head.parent = root
    head.roll = 0.3
    parent = head
    position = Vector((0.08, -0.02, 1.55))
    for i in range(bones):
        direction = Vector((0.06 * math.sin(0.7 * i), 0.04, -1.0)).normalized()
        bone = data.edit_bones.new(f"J_Sec_Hair1_{i + 1:02d}")
        bone.head = position
        bone.tail = position + 0.05 * direction
        bone.roll = float(rng.uniform(-math.pi, math.pi))
        bone.parent = parent
        bone.use_connect = False
        parent, position = (
            bone,
            bone.tail + gap * direction.cross(Vector((1, 0, 0))).normalized() + gap * direction,
        )
    bpy.ops.object.mode_set(mode="POSE")
    return obj


def _chain(obj):
    return [pb for pb in obj.pose.bones if pb.name.startswith("J_Sec_Hair1_")]


def _add_rod(obj):
    select_only(obj, {"J_Sec_Hair1_01"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    return obj.kodawari_hair.rods[0]


def test_an_unconnected_rolled_chain_starts_from_its_rest_pose_without_a_pop(empty_scene):
    obj = make_vrm_like_rig(empty_scene)
    _add_rod(obj)
    add_camera(empty_scene, "Front", (0, -4, 1.5))
    empty_scene.frame_start, empty_scene.frame_end = 1, 24
    frames = []
    for frame in (1, 2, 3):
        empty_scene.frame_set(frame)
        frames.append([tuple(pb.matrix.to_quaternion()) for pb in _chain(obj)])
        if frame == 1:  # frame 1 is the rest pose itself
            assert (
                max(angle_deg(tuple(pb.rotation_quaternion), (1, 0, 0, 0)) for pb in _chain(obj))
                < 1e-3
            )
    for a, b in zip(frames, frames[1:]):
        change = max(angle_deg(qa, qb) for qa, qb in zip(a, b))
        assert change < 5.0, f"a joint turned {change:.1f} degrees in one frame with the head still"


def test_a_rod_follows_its_root_bone_through_a_rename(empty_scene):
    from kodawari.hair import runtime

    obj = make_vrm_like_rig(empty_scene, bones=6)
    rod = _add_rod(obj)
    add_camera(empty_scene, "Front", (0, -4, 1.5))
    obj.data.bones["J_Sec_Hair1_01"].name = "Hair_Side_L.001"
    runtime.clear()  # what undo (pushed by the rename) does: runtimes rebuild from settings
    head = obj.pose.bones["J_Bip_C_Head"]
    for frame, location in ((1, (0, 0, 0)), (6, (0.3, 0, 0))):
        head.location = location
        head.keyframe_insert("location", frame=frame)
    for frame in range(1, 13):
        empty_scene.frame_set(frame)
    rt = runtime.get(obj)
    assert rt.error == ""
    assert rod.root_bone == "Hair_Side_L.001"
    assert list(rt.rod_slots) == [0], "the renamed rod must still be simulated"
    moved = max(angle_deg(tuple(pb.rotation_quaternion), (1, 0, 0, 0)) for pb in _chain(obj)[1:])
    assert moved > 1.0, "the head's motion should swing the renamed chain"


def test_a_rod_whose_root_is_gone_is_reported_once_during_playback(empty_scene, capsys):
    from kodawari import problems
    from kodawari.hair import chains, runtime

    obj = make_vrm_like_rig(empty_scene, bones=4)
    rod = _add_rod(obj)
    add_camera(empty_scene, "Front", (0, -4, 1.5))
    del obj.pose.bones["J_Sec_Hair1_01"][chains.ROD_ID_PROPERTY]  # as a file from before rod IDs
    obj.data.bones["J_Sec_Hair1_01"].name = "Hair_Side_L.001"
    runtime.clear()
    for frame in range(1, 11):
        empty_scene.frame_set(frame)
    assert "J_Sec_Hair1_01" in problems.message(obj, "hair")
    lines = [line for line in capsys.readouterr().out.splitlines() if "stopped" in line]
    assert len(lines) == 1, lines
    assert rod.root_bone == "J_Sec_Hair1_01"
