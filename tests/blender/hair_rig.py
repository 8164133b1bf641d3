"""A small character rig for the hair tests: Root -> Head, and chains on the head."""

import math

import bpy
from mathutils import Euler, Vector


def make_rig(
    scene, chains=(("Ahoge", (0.0, 0.0, 1.8), (0.0, 0.0, 1.0), 5),), bone_length=0.06, branch=False
):
    """chains: (name, start, direction, bones). Returns the armature object in pose mode."""
    data = bpy.data.armatures.new("Rig")
    obj = bpy.data.objects.new("Rig", data)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.object.mode_set(mode="EDIT")
    root = data.edit_bones.new("Root")
    root.head, root.tail = (0, 0, 0), (0, 0, 0.5)
    head = data.edit_bones.new("Head")
    head.head, head.tail = (0, 0, 1.5), (0, 0, 1.7)
    head.parent = root
    for name, start, direction, count in chains:
        parent = head
        position = Vector(start)
        step = Vector(direction).normalized() * bone_length
        for i in range(count):
            bone = data.edit_bones.new(f"{name}.{i:02d}")
            bone.head, bone.tail = position, position + step
            bone.parent = parent
            bone.use_connect = i > 0
            parent, position = bone, position + step
        if branch:
            extra = data.edit_bones.new(f"{name}.branch")
            extra.head, extra.tail = position - step, position - step + Vector((bone_length, 0, 0))
            extra.parent = data.edit_bones[f"{name}.{count - 2:02d}"]
    bpy.ops.object.mode_set(mode="POSE")
    return obj


def add_camera(scene, name, location, look_at=(0.0, 0.0, 1.7), active=True):
    cam = bpy.data.objects.new(name, bpy.data.cameras.new(name))
    scene.collection.objects.link(cam)
    cam.location = location
    direction = Vector(look_at) - Vector(location)
    cam.rotation_euler = direction.to_track_quat("-Z", "Y").to_euler()
    if active:
        scene.camera = cam
    bpy.context.view_layer.update()
    return cam


def key_head(obj, keys, by="action"):
    """Keys the Head bone (Pose Mode) at `keys`, (frame, location, rotation_euler) triples.
    by="constraint": keys a HeadControl bone with the head's rest instead, which the head
    copies (Copy Transforms, local), as in rigs whose head a control moves. The keyed bone."""
    head = driver = obj.pose.bones["Head"]
    head.rotation_mode = "XYZ"
    if by == "constraint":
        bpy.ops.object.mode_set(mode="EDIT")
        control = obj.data.edit_bones.new("HeadControl")
        rest = obj.data.edit_bones["Head"]
        control.head, control.tail, control.roll = rest.head, rest.tail, rest.roll
        control.parent = rest.parent
        bpy.ops.object.mode_set(mode="POSE")
        head = obj.pose.bones["Head"]
        driver = obj.pose.bones["HeadControl"]
        driver.rotation_mode = "XYZ"
        con = head.constraints.new("COPY_TRANSFORMS")
        con.target, con.subtarget = obj, "HeadControl"
        con.target_space = con.owner_space = "LOCAL"
    for frame, location, rotation in keys:
        driver.location, driver.rotation_euler = location, rotation
        driver.keyframe_insert("location", frame=frame)
        driver.keyframe_insert("rotation_euler", frame=frame)
    return driver


def select_only(obj, names):
    from kodawari.hair import chains

    for pb in obj.pose.bones:
        chains.set_selected(pb, pb.name in names)


def chain_bones(obj, name):
    return [
        pb
        for pb in obj.pose.bones
        if pb.name.startswith(name + ".") and not pb.name.endswith("branch")
    ]


def rotations(obj, name):
    import numpy as np

    return np.array([tuple(pb.rotation_quaternion) for pb in chain_bones(obj, name)])


def angle_deg(q1, q2):
    import numpy as np

    q1, q2 = np.asarray(q1, float), np.asarray(q2, float)
    d = abs(float(np.dot(q1 / np.linalg.norm(q1), q2 / np.linalg.norm(q2))))
    return math.degrees(2 * math.acos(min(1.0, d)))


def pose_curl(obj, name, axis="X", degrees=20.0):
    """Poses the chain into a curl (each joint turned about its local axis)."""
    for pb in chain_bones(obj, name):
        pb.rotation_mode = "QUATERNION"
        pb.rotation_quaternion = Euler(
            tuple(math.radians(degrees) if a == axis else 0.0 for a in "XYZ")
        ).to_quaternion()
    bpy.context.view_layer.update()


def run_frames(scene, first, last):
    for frame in range(first, last + 1):
        scene.frame_set(frame)


def ahoge_under_a_moving_head(scene):
    """The rig with a live rod on its ahoge, the head keyed to move over frames 1-24 and a
    front camera; scene frames 1-40."""
    obj = make_rig(scene)
    select_only(obj, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    head = obj.pose.bones["Head"]
    for frame, location in (
        (1, (0, 0, 0)),
        (8, (0.4, 0, 0.2)),
        (16, (-0.4, 0.2, 0)),
        (24, (0, 0, 0)),
    ):
        head.location = location
        head.keyframe_insert("location", frame=frame)
    add_camera(scene, "Front", (0, -4, 1.7))
    scene.frame_start, scene.frame_end = 1, 40
    return obj
