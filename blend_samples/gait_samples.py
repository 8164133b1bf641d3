"""Sample rigs the demo, tests and benchmark build: a Thoroughbred (4 bones per leg,
a moving scapula) and a small dog (3 bones per leg), each with a Skin-modifier body.
Bones are laid out facing -Y (Blender's front), z up, feet on z = 0."""

import math

import bpy
import numpy as np

# (length m, absolute rest angle from straight down in degrees; positive = tip backward)
HORSE_FORE = (
    ("scapula", 0.45, -35.0),
    ("humerus", 0.30, 45.0),
    ("radius", 0.40, -5.0),
    ("cannon", 0.45, 10.0),
)
HORSE_HIND = (
    ("pelvis", 0.40, 60.0),
    ("femur", 0.42, -25.0),
    ("tibia", 0.40, 35.0),
    ("cannon", 0.50, -5.0),
)
DOG_FRONT = (("upper", 0.18, 35.0), ("lower", 0.18, -5.0), ("paw", 0.12, 15.0))
DOG_BACK = (("thigh", 0.20, -30.0), ("shin", 0.20, 40.0), ("paw", 0.14, -10.0))

# The dog's own gait table (m/s bands for a ~0.45 m leg; AUTO uses the rotary gallop).
DOG_TABLE = {
    "WALK": dict(duty_factor=0.65, swing_time=0.25, swing_height=0.05, bob=0.01, speed_max=0.9),
    "TROT": dict(duty_factor=0.45, swing_time=0.22, swing_height=0.07, bob=0.015, speed_max=2.4),
    "CANTER": dict(duty_factor=0.35, swing_time=0.22, swing_height=0.08, bob=0.02, speed_max=3.6),
    "GALLOP": dict(
        duty_factor=0.25,
        swing_time=0.2,
        swing_height=0.08,
        bob=0.02,
        speed_max=7.0,
        use_in_auto=False,
    ),
    "GALLOP_ROTARY": dict(
        duty_factor=0.22,
        swing_time=0.2,
        swing_height=0.08,
        bob=0.02,
        speed_max=7.0,
        phase_fore_hind=0.4,
        phase_left_right=0.1,
        use_in_auto=True,
    ),
}


def _drop(bones):
    return sum(length * math.cos(math.radians(angle)) for _, length, angle in bones)


def _leg_points(root, bones):
    points = [np.array(root, dtype=float)]
    for _, length, angle in bones:
        a = math.radians(angle)
        points.append(points[-1] + np.array([0.0, length * math.sin(a), -length * math.cos(a)]))
    return points


def build_rig(
    name, scene, fore, hind, fore_y, hind_y, fore_x, hind_x, body_z, names, skin_radii, extra=()
):
    """Armature + skinned mesh. names: (fore word, hind word, side format, body name)."""
    fore_word, hind_word, side_format, body_name = names
    armature = bpy.data.armatures.new(name)
    rig = bpy.data.objects.new(name, armature)
    scene.collection.objects.link(rig)
    previous_active = bpy.context.view_layer.objects.active
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    eb = armature.edit_bones
    body = eb.new(body_name)
    body.head = (0.0, 0.0, body_z)
    body.tail = (0.0, fore_y * 1.1, body_z)
    skeleton = {"verts": [], "edges": [], "groups": [], "radii": []}

    def add_vertex(p, group, radius):
        skeleton["verts"].append(tuple(p))
        skeleton["groups"].append(group)
        skeleton["radii"].append(radius)
        return len(skeleton["verts"]) - 1

    spine = [
        add_vertex((0.0, y, body_z + 0.05), body_name, skin_radii[0])
        for y in np.linspace(hind_y * 1.25, fore_y * 1.3, 6)
    ]
    for a, b in zip(spine[:-1], spine[1:]):
        skeleton["edges"].append((a, b))
    tails = {}
    for bone_name, head, tail, radius, parent in extra:
        # parent: a spine vertex index, or the name of an earlier extra bone to chain to
        bone = eb.new(bone_name)
        bone.head, bone.tail = head, tail
        bone.parent = eb[parent] if isinstance(parent, str) else body
        bone.use_connect = isinstance(parent, str)
        v0 = tails[parent] if isinstance(parent, str) else spine[parent]
        v1 = add_vertex(tail, bone_name, radius)
        tails[bone_name] = v1
        skeleton["edges"].append((v0, v1))
    for side, sign in (("L", 1.0), ("R", -1.0)):
        for word, bones, y, x in (
            (fore_word, fore, fore_y, fore_x),
            (hind_word, hind, hind_y, hind_x),
        ):
            root = (sign * x, y, _drop(bones))
            points = _leg_points(root, bones)
            parent = body
            previous_vertex = spine[-2] if word == fore_word else spine[1]
            for k, (bone_name, _, _) in enumerate(bones):
                bone = eb.new(f"{word}_{bone_name}" + side_format.format(side))
                bone.head, bone.tail = tuple(points[k]), tuple(points[k + 1])
                bone.roll = 0.0
                bone.parent = parent
                bone.use_connect = k > 0
                parent = bone
                r = skin_radii[1] + (skin_radii[2] - skin_radii[1]) * (k + 1) / len(bones)
                v = add_vertex(points[k + 1], bone.name, r)
                if k == 0:
                    v_root = add_vertex(points[0], body_name, skin_radii[1] * 1.3)
                    skeleton["edges"].append((previous_vertex, v_root))
                    previous_vertex = v_root
                skeleton["edges"].append((previous_vertex, v))
                previous_vertex = v
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.objects.active = previous_active

    mesh = bpy.data.meshes.new(name + "Skin")
    mesh.from_pydata(skeleton["verts"], skeleton["edges"], [])
    body_obj = bpy.data.objects.new(name + "Body", mesh)
    scene.collection.objects.link(body_obj)
    body_obj.parent = rig
    for group_name in dict.fromkeys(skeleton["groups"]):
        group = body_obj.vertex_groups.new(name=group_name)
        group.add([i for i, g in enumerate(skeleton["groups"]) if g == group_name], 1.0, "REPLACE")
    arm_mod = body_obj.modifiers.new("Armature", "ARMATURE")
    arm_mod.object = rig
    skin = body_obj.modifiers.new("Skin", "SKIN")
    skin.use_smooth_shade = True
    for i, r in enumerate(skeleton["radii"]):
        mesh.skin_vertices[0].data[i].radius = (r, r)
    mesh.skin_vertices[0].data[spine[0]].use_root = True
    sub = body_obj.modifiers.new("Subdivision", "SUBSURF")
    sub.levels = 1
    sub.render_levels = 2
    return rig, body_obj


def build_horse(scene, name="Horse"):
    """A Thoroughbred: withers ~1.5 m, 4 bones per leg named fore_*.L / hind_*.R."""
    extra = (
        ("neck", (0.0, -0.66, 1.5), (0.0, -1.05, 1.95), 0.14, 5),
        ("head", (0.0, -1.05, 1.95), (0.0, -1.5, 1.62), 0.1, "neck"),
        ("tail", (0.0, 0.7, 1.45), (0.0, 1.05, 1.05), 0.05, 0),
    )
    rig, body = build_rig(
        name,
        scene,
        HORSE_FORE,
        HORSE_HIND,
        -0.55,
        0.55,
        0.12,
        0.14,
        1.45,
        ("fore", "hind", ".{}", "body"),
        (0.32, 0.085, 0.045),
        extra,
    )
    return rig, body


def build_dog(scene, name="Dog"):
    """A small dog: 3 bones per leg named front_*_L / back_*_R (other naming on purpose)."""
    extra = (
        ("neck", (0.0, -0.25, 0.55), (0.0, -0.38, 0.72), 0.06, 5),
        ("head", (0.0, -0.38, 0.72), (0.0, -0.55, 0.66), 0.05, "neck"),
        ("tail", (0.0, 0.28, 0.52), (0.0, 0.5, 0.6), 0.02, 0),
    )
    return build_rig(
        name,
        scene,
        DOG_FRONT,
        DOG_BACK,
        -0.22,
        0.22,
        0.07,
        0.07,
        0.55,
        ("front", "back", "_{}", "spine"),
        (0.12, 0.035, 0.02),
        extra,
    )


def apply_dog_table(settings):
    for entry in settings.table:
        for key, value in DOG_TABLE.get(entry.name, {}).items():
            setattr(entry, key, value)
        entry.froude_max = entry.speed_max**2 / (9.81 * 0.45)


def key_speed(obj, frames_and_speeds):
    """Keys Object.kodawari_gait.speed (m/s) at (frame, speed) pairs."""
    settings = obj.kodawari_gait
    for frame, speed in frames_and_speeds:
        settings.speed = speed
        obj.keyframe_insert(data_path="kodawari_gait.speed", frame=frame)


def rigify_metarig(scene, animal):
    """Blender's bundled Rigify animal metarig ("wolf", "horse", "cat"), built by Rigify's
    own metarig script (Rigify ships with Blender as an add-on; it is enabled here)."""
    import importlib

    import addon_utils

    addon_utils.enable("rigify", default_set=True)
    module = importlib.import_module(f"rigify.metarigs.Animals.{animal}")
    armature = bpy.data.armatures.new(f"{animal}_metarig")
    obj = bpy.data.objects.new(f"{animal.capitalize()}Metarig", armature)
    scene.collection.objects.link(obj)
    previous = bpy.context.view_layer.objects.active
    bpy.context.view_layer.objects.active = obj
    module.create(obj)
    bpy.ops.object.mode_set(mode="OBJECT")
    bpy.context.view_layer.objects.active = previous
    return obj


def skin_armature(rig, scene, bone_names, radius):
    """A simple skinned body for an armature: a Skin-modifier mesh with a vertex at each
    listed bone's head and tail, edges along the bones, each vertex weighted fully to its
    bone; radii taper from `radius` on the trunk to a third of it at the feet."""
    bones = rig.data.bones
    wanted = [b for b in bones if b.name in bone_names]
    verts, groups, radii, edges = [], [], [], []
    at = {}

    def vertex(p, group, r):
        key = tuple(round(c, 4) for c in p)
        if key in at:
            return at[key]
        verts.append(tuple(p))
        groups.append(group)
        radii.append(r)
        at[key] = len(verts) - 1
        return at[key]

    lowest = min(b.tail_local.z for b in wanted)
    highest = max(b.head_local.z for b in wanted)
    for b in wanted:

        def r_at(z):
            return radius * (
                0.3 + 0.7 * min(1.0, max(0.0, (z - lowest) / max(highest - lowest, 1e-6))) ** 2
            )

        a = vertex(b.head_local, b.name, r_at(b.head_local.z))
        c = vertex(b.tail_local, b.name, r_at(b.tail_local.z))
        if a != c:
            edges.append((a, c))
        p = b.parent
        while p is not None and p.name not in bone_names:
            p = p.parent  # skip bones left out of the body (Rigify's pelvis.L)
        if p is not None and (p is not b.parent or not b.use_connect):
            # join an unconnected child to the nearest end of its (kept) parent
            near = min((p.head_local, p.tail_local), key=lambda q: (q - b.head_local).length)
            edges.append((vertex(near, p.name, r_at(near.z)), a))
    mesh = bpy.data.meshes.new(rig.name + "Skin")
    mesh.from_pydata(verts, sorted({tuple(sorted(e)) for e in edges if e[0] != e[1]}), [])
    body = bpy.data.objects.new(rig.name + "Body", mesh)
    scene.collection.objects.link(body)
    body.parent = rig
    for name in dict.fromkeys(groups):
        group = body.vertex_groups.new(name=name)
        group.add([i for i, g in enumerate(groups) if g == name], 1.0, "REPLACE")
    body.modifiers.new("Armature", "ARMATURE").object = rig
    skin = body.modifiers.new("Skin", "SKIN")
    skin.use_smooth_shade = True
    for i, r in enumerate(radii):
        mesh.skin_vertices[0].data[i].radius = (r, r)
    mesh.skin_vertices[0].data[0].use_root = True
    sub = body.modifiers.new("Subdivision", "SUBSURF")
    sub.levels, sub.render_levels = 1, 2
    return body
