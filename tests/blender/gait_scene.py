"""Helpers for the gait tests: sample rigs set up and keyed."""

import os
import sys

import bpy

# The sample rig builders live with the demos (blend_samples/), not in the add-on.
sys.path.insert(
    0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "blend_samples")
)


def horse(scene, speeds=None, fps=24):
    import gait_samples as samples

    scene.render.fps = fps
    scene.render.fps_base = 1.0
    rig, body = samples.build_horse(scene)
    bpy.context.view_layer.objects.active = rig
    assert bpy.ops.kodawari.gait_setup() == {"FINISHED"}
    if speeds:
        samples.key_speed(rig, speeds)
    return rig


def fcurve_snapshot(obj):
    """{(data_path, index): values} of every F-curve on obj's action."""
    from kodawari import fcurves

    anim = obj.animation_data
    if anim is None or anim.action is None:
        return {}
    return {
        (c.data_path, c.array_index): fcurves.read_keys(c)[1].tolist()
        for c in fcurves.action_fcurves(anim.action, obj)
    }


# --- rigs nobody on the project made --------------------------------------------------
def rigify_metarig(scene, animal, scale=1.0):
    """Blender's bundled Rigify animal metarig ("wolf", "horse", "cat"), built by Rigify's
    own metarig script into a new armature, at object scale `scale` (the metarig's size
    kept in the world: its bones are built 1/scale larger)."""
    import importlib

    import addon_utils

    addon_utils.enable("rigify", default_set=True)
    module = importlib.import_module(f"rigify.metarigs.Animals.{animal}")
    armature = bpy.data.armatures.new(f"{animal}_metarig")
    obj = bpy.data.objects.new(f"{animal}_metarig", armature)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    module.create(obj)
    bpy.ops.object.mode_set(mode="OBJECT")
    if scale != 1.0:
        _rescale(obj, scale)
    return obj


def _rescale(obj, scale):
    """Bones 1/scale larger, object scale `scale`: the same animal in the world, the way
    a centimetre FBX/glTF import arrives."""
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    bones = obj.data.edit_bones
    # All ends read before any is written: a connected child's head is its parent's
    # tail, so scaling bone by bone would scale that shared point twice.
    ends = {b.name: (b.head / scale, b.tail / scale) for b in bones}
    for bone in bones:
        bone.head, bone.tail = ends[bone.name]
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.scale = (scale, scale, scale)


# Naming conventions of rigs users bring: (body bones hips..spine2, neck, head),
# fore (girdle, upper, lower, paw), hind (upper, lower, foot, toe); {s}/{S}/{Side} = side.
CONVENTIONS = {
    "mixamo": (
        (
            "mixamorig:Hips",
            "mixamorig:Spine",
            "mixamorig:Spine1",
            "mixamorig:Spine2",
            "mixamorig:Neck",
            "mixamorig:Head",
        ),
        (
            "mixamorig:{Side}Shoulder",
            "mixamorig:{Side}Arm",
            "mixamorig:{Side}ForeArm",
            "mixamorig:{Side}Hand",
        ),
        (
            "mixamorig:{Side}UpLeg",
            "mixamorig:{Side}Leg",
            "mixamorig:{Side}Foot",
            "mixamorig:{Side}ToeBase",
        ),
    ),
    "unreal": (
        ("pelvis", "spine_01", "spine_02", "spine_03", "neck_01", "head"),
        ("clavicle_{s}", "upperarm_{s}", "lowerarm_{s}", "hand_{s}"),
        ("thigh_{s}", "calf_{s}", "foot_{s}", "ball_{s}"),
    ),
    "max_biped": (
        ("Bip01 Pelvis", "Bip01 Spine", "Bip01 Spine1", "Bip01 Spine2", "Bip01 Neck", "Bip01 Head"),
        ("Bip01 {S} Clavicle", "Bip01 {S} UpperArm", "Bip01 {S} Forearm", "Bip01 {S} Hand"),
        ("Bip01 {S} Thigh", "Bip01 {S} Calf", "Bip01 {S} Foot", "Bip01 {S} Toe0"),
    ),
    "game": (
        ("b_Hips_01", "b_Spine_02", "b_Spine1_03", "b_Spine2_04", "b_Neck_05", "b_Head_06"),
        ("b_{Side}Shoulder_07", "b_{Side}UpperArm_09", "b_{Side}ForeArm_10", "b_{Side}Hand_11"),
        ("b_{Side}Leg01_20", "b_{Side}Leg02_21", "b_{Side}Foot_22", "b_{Side}Toe_23"),
    ),
}
# A fox-sized quadruped (metres, facing -Y): legs as (length, absolute angle from
# straight down, + = tip backward).
_FORE = ((0.17, 40.0), (0.17, -15.0), (0.09, 20.0))
_HIND = ((0.19, -32.0), (0.19, 42.0), (0.12, -12.0), (0.05, -70.0))


def _leg(root, bones):
    import math

    points = [tuple(root)]
    for length, angle in bones:
        a = math.radians(angle)
        x, y, z = points[-1]
        points.append((x, y + length * math.sin(a), z - length * math.cos(a)))
    return points


def named_rig(scene, convention, scale=1.0, connected_body=False, roll=0.3):
    """A quadruped with a convention's bone names, built in units of `scale` metres (so
    at object scale `scale` it is fox-sized in the world). connected_body: the hind legs
    hang from a spine bone connected to the hips (the legs' deepest common parent is
    then a connected bone, whose location Blender ignores). Bones get an arbitrary roll."""
    import math

    body, fore, hind = CONVENTIONS[convention]
    u = 1.0 / scale
    hind_z = sum(length * math.cos(math.radians(a)) for length, a in _HIND)
    fore_z = sum(length * math.cos(math.radians(a)) for length, a in _FORE)
    armature = bpy.data.armatures.new(convention)
    obj = bpy.data.objects.new(convention, armature)
    scene.collection.objects.link(obj)
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="EDIT")
    eb = armature.edit_bones

    def bone(name, head, tail, parent=None, connect=False):
        b = eb.new(name)
        b.head = tuple(v * u for v in head)
        b.tail = tuple(v * u for v in tail)
        b.roll = roll
        b.parent = eb[parent] if parent else None
        b.use_connect = connect
        return b

    spine_z = hind_z + 0.06
    ys = (0.26, 0.12, -0.02, -0.16, -0.24)
    bone(body[0], (0, ys[0], spine_z), (0, ys[1], spine_z))
    for k in range(1, 4):
        bone(body[k], (0, ys[k], spine_z), (0, ys[k + 1], spine_z), body[k - 1], connect=True)
    bone(body[4], (0, ys[4], spine_z), (0, -0.33, spine_z + 0.12), body[3], connect=True)
    bone(body[5], (0, -0.33, spine_z + 0.12), (0, -0.45, spine_z + 0.08), body[4], connect=True)
    hind_parent = body[1] if connected_body else body[0]
    for side, sign in (("L", 1.0), ("R", -1.0)):
        fill = {"s": side.lower(), "S": side, "Side": "Left" if side == "L" else "Right"}
        names = [n.format(**fill) for n in fore]
        points = _leg((sign * 0.07, -0.19, fore_z), _FORE)
        bone(names[0], (sign * 0.015, -0.17, spine_z - 0.02), points[0], body[3])
        parent = names[0]
        for k, name in enumerate(names[1:]):
            bone(name, points[k], points[k + 1], parent, connect=k > 0)
            parent = name
        names = [n.format(**fill) for n in hind]
        points = _leg((sign * 0.07, 0.22, hind_z), _HIND)
        parent = hind_parent
        for k, name in enumerate(names):
            bone(name, points[k], points[k + 1], parent, connect=k > 0)
            parent = name
    bpy.ops.object.mode_set(mode="OBJECT")
    obj.scale = (scale, scale, scale)
    return obj


def expected_feet(convention):
    """The foot (last leg bone) of LF, RF, LH, RH for a convention or Rigify metarig."""
    if convention in CONVENTIONS:
        _, fore, hind = CONVENTIONS[convention]
        out = []
        for names, side in ((fore, "L"), (fore, "R"), (hind, "L"), (hind, "R")):
            out.append(
                names[-1].format(s=side.lower(), S=side, Side="Left" if side == "L" else "Right")
            )
        return out
    return {
        "wolf": ["front_toe.L", "front_toe.R", "toe.L", "toe.R"],
        "cat": ["f_toe.L", "f_toe.R", "r_toe.L", "r_toe.R"],
        "horse": ["f_hoof.L", "f_hoof.R", "r_hoof.L", "r_hoof.R"],
    }[convention]


def select_pose_bones(obj, names):
    bpy.context.view_layer.objects.active = obj
    bpy.ops.object.mode_set(mode="POSE")
    for pose_bone in obj.pose.bones:
        owner = pose_bone if hasattr(pose_bone, "select") else pose_bone.bone  # 5.0 moved selection
        owner.select = pose_bone.name in names


def build(scene, case):
    """A test rig by case name: "wolf", "mixamo@0.01", "unreal+connected", ..."""
    name, _, rest = case.partition("@")
    scale = 1.0
    connected = name.endswith("+connected")
    name = name.replace("+connected", "")
    if rest:
        scale = float(rest.replace("+connected", ""))
        connected = connected or rest.endswith("+connected")
    if name in CONVENTIONS:
        return named_rig(scene, name, scale=scale, connected_body=connected)
    return rigify_metarig(scene, name, scale=scale)


# --- measuring what Blender shows ----------------------------------------------------
def evaluated_legs(obj, frames):
    """World points of each leg (heads of its bones, then the foot's tail) per frame,
    from the evaluated pose (scene.frame_set): {leg: (F, n + 1, 3)}."""
    import numpy as np

    scene = bpy.context.scene
    chains = {leg.name: [b.name for b in leg.bones] for leg in obj.kodawari_gait.legs}
    names = list(obj.pose.bones.keys())
    n = len(names)
    heads = np.empty(n * 3, dtype=np.float32)
    tails = np.empty(n * 3, dtype=np.float32)
    out = {k: np.empty((len(frames), len(v) + 1, 3)) for k, v in chains.items()}
    index = {k: [names.index(b) for b in v] for k, v in chains.items()}
    for i, f in enumerate(frames):
        scene.frame_set(int(f))
        world = np.array([[obj.matrix_world[r][c] for c in range(4)] for r in range(4)])
        obj.pose.bones.foreach_get("head", heads)
        obj.pose.bones.foreach_get("tail", tails)
        h = heads.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]
        t = tails.reshape(-1, 3) @ world[:3, :3].T + world[:3, 3]
        for k in chains:
            out[k][i, :-1] = h[index[k]]
            out[k][i, -1] = t[index[k][-1]]
    return out


def joint_angles(points, heading):
    """Each joint's bend in the leg's plane (degrees): bone directions (F, n) from straight
    down, positive tip backward, then differences down the chain (the first: the bone's
    angle itself)."""
    import numpy as np

    d = np.diff(points, axis=1)
    along = np.einsum("fnc,fc->fn", d, heading)
    absolute = np.degrees(np.unwrap(np.arctan2(-along, -d[..., 2]), axis=0))
    return np.concatenate([absolute[:, :1], np.diff(absolute, axis=1)], axis=1)


def headings(legs):
    import numpy as np

    h = (legs["LF"][:, 0] + legs["RF"][:, 0] - legs["LH"][:, 0] - legs["RH"][:, 0]) / 2
    h[:, 2] = 0
    return h / np.linalg.norm(h, axis=1, keepdims=True)


def stance_end_ratio(angles, planted):
    """The issue's 3x rule on every planted-leg joint change, the ends of each stance
    included: the largest ratio of a change into a planted frame (the touch-down change,
    from the swing's last pose, too) to 3x the larger of its neighbouring frames' changes
    + 1 deg, whichever frames those are (the change at lift-off included)."""
    import numpy as np

    step = np.abs(np.diff(angles, axis=0))  # (F-1, n): change from frame f to f+1
    counted = planted[1:].copy()
    counted[[0, -1]] = False  # the timeline's first and last changes have one neighbour
    if not counted.any():
        return 0.0
    neighbours = np.maximum(np.vstack([step[:1], step[:-1]]), np.vstack([step[1:], step[-1:]]))
    return float((step / (3 * neighbours + 1.0))[counted].max())


def planted_snaps(angles, planted, min_stance=1, touchdown=False):
    """(largest planted-joint change between frames, largest ratio of a change inside a
    stance to 3x the larger of its neighbouring frames' changes + 1 deg). The ratio
    counts changes with the foot planted at both ends and planted neighbours on both
    sides, in stances of at least `min_stance` frames: a joint snapping while its foot
    is planted. With `touchdown`, the largest change also counts the change into each
    touch-down frame (from the swing's last pose to the first planted one)."""
    import numpy as np

    step = np.abs(np.diff(angles, axis=0))  # (F-1, n): change from frame f to f+1
    runs = np.zeros(len(planted), dtype=int)
    i = 0
    while i < len(planted):
        j = i
        while j < len(planted) and planted[j] == planted[i]:
            j += 1
        runs[i:j] = j - i
        i = j
    both = planted[:-1] & planted[1:]
    counted = planted[1:] if touchdown else both
    if not counted.any():
        return 0.0, 0.0
    largest = float(step[counted].max())
    inside = both & (runs[:-1] >= min_stance)
    inside[1:-1] &= both[:-2] & both[2:]
    inside[[0, -1]] = False
    if not inside.any():
        return largest, 0.0
    neighbours = np.maximum(np.vstack([step[:1], step[:-1]]), np.vstack([step[1:], step[-1:]]))
    ratio = step / (3 * neighbours + 1.0)
    return largest, float(ratio[inside].max())
