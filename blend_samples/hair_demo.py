"""View-dependent hair demo (runs inside Blender 3.4 with the add-on enabled).

A simple character head with an ahoge (cowlick) that reads sideways from every side,
bangs that stay off the eyes from the front, and rabbit ears with three keyed views.
The head moves and the camera orbits. Two identical rigs share the spot: "plain"
(physics only) and "kodawari" (the same physics plus the keyed view shapes); each is
rendered alone from four camera angles. Writes out/hair.blend and out/hair_sheet.png
(top row plain physics, bottom row view-dependent; columns front, right, back, left;
the rows and columns are labelled on the sheet). Every character wears an 18-bone
ponytail; a third one lunges and holds still while its ponytail swings and settles,
rendered live into out/hair_swing.gif and out/hair_swing.png (six moments, 0-6 s).
"""

import math
import os
import subprocess

import bpy
import numpy as np
from kodawari import fcurves
from kodawari.hair import chains
from mathutils import Matrix, Quaternion, Vector

OUT = os.environ.get("KODAWARI_OUT", os.path.join(os.getcwd(), "out"))
TILE = (480, 270)
FRAMES = {"front": 25, "right": 49, "back": 73, "left": 97}  # orbit angles 0, 90, 180, 270 degrees
HEAD_CENTRE = Vector((0.0, 0.0, 1.75))
HEAD_RADIUS = 0.22

# (name, start, direction, bones, bone length)
CHAINS = (
    ("Ahoge", (0.0, 0.02, 1.96), (0.0, 0.0, 1.0), 5, 0.055),
    ("BangL", (-0.08, -0.17, 1.9), (0.0, -0.35, -1.0), 4, 0.05),
    ("BangM", (0.0, -0.19, 1.9), (0.0, -0.35, -1.0), 4, 0.05),
    ("BangR", (0.08, -0.17, 1.9), (0.0, -0.35, -1.0), 4, 0.05),
    ("EarL", (-0.09, 0.02, 1.94), (-0.25, 0.0, 1.0), 5, 0.07),
    ("EarR", (0.09, 0.02, 1.94), (0.25, 0.0, 1.0), 5, 0.07),
    # A ponytail of 18 short bones hanging from the back of the head (0.63 m).
    ("Tail", (0.0, 0.235, 1.82), (0.0, 0.2, -1.0), 18, 0.035),
)
SWING_FRAMES = range(1, 145, 2)  # 6 s of the swing demo, every other frame (12 fps GIF)


def material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    mat.node_tree.nodes["Principled BSDF"].inputs["Base Color"].default_value = (*color, 1.0)
    mat.diffuse_color = (*color, 1.0)  # what the Workbench (swing demo) shows
    return mat


def parent_to_bone(child, rig, bone_name, keep_world=True):
    """Bone parenting (the child's frame is the bone's tail). keep_world: a child built in
    world space stays where it is; otherwise its local frame is the bone's tail frame."""
    child.parent = rig
    child.parent_type = "BONE"
    child.parent_bone = bone_name
    bone = rig.data.bones[bone_name]
    tail = rig.matrix_world @ bone.matrix_local @ Matrix.Translation((0.0, bone.length, 0.0))
    child.matrix_parent_inverse = tail.inverted() if keep_world else Matrix.Identity(4)


def cylinder(name, length, radius, mat, collection):
    """A thin cylinder along -Y from the origin (a bone child sits at the bone's tail)."""
    mesh = bpy.data.meshes.new(name)
    ring = 8
    verts = []
    for y in (-length, 0.0):
        for i in range(ring):
            a = 2 * math.pi * i / ring
            verts.append((radius * math.cos(a), y, radius * math.sin(a)))
    faces = [(i, (i + 1) % ring, ring + (i + 1) % ring, ring + i) for i in range(ring)]
    faces += [tuple(range(ring - 1, -1, -1)), tuple(range(ring, 2 * ring))]
    mesh.from_pydata(verts, [], faces)
    mesh.materials.append(mat)
    obj = bpy.data.objects.new(name, mesh)
    collection.objects.link(obj)
    return obj


def sphere(name, location, radius, mat, collection):
    bpy.ops.mesh.primitive_uv_sphere_add(
        radius=radius, location=location, segments=24, ring_count=12
    )
    obj = bpy.context.active_object
    obj.name = name
    obj.data.materials.append(mat)
    bpy.ops.object.shade_smooth()
    for c in obj.users_collection:
        c.objects.unlink(obj)
    collection.objects.link(obj)
    return obj


def build_character(label, mats):
    collection = bpy.data.collections.new(label)
    bpy.context.scene.collection.children.link(collection)
    data = bpy.data.armatures.new(f"{label}Rig")
    rig = bpy.data.objects.new(f"{label}Rig", data)
    collection.objects.link(rig)
    bpy.context.view_layer.objects.active = rig
    bpy.ops.object.mode_set(mode="EDIT")
    root = data.edit_bones.new("Root")
    root.head, root.tail = (0, 0, 0), (0, 0, 0.8)
    head = data.edit_bones.new("Head")
    head.head, head.tail = (0, 0, 1.5), (0, 0, 1.8)
    head.parent = root
    for name, start, direction, count, length in CHAINS:
        parent, position = head, Vector(start)
        step = Vector(direction).normalized() * length
        for i in range(count):
            bone = data.edit_bones.new(f"{name}.{i}")
            bone.head, bone.tail = position, position + step
            bone.parent, bone.use_connect = parent, i > 0
            parent, position = bone, position + step
    bpy.ops.object.mode_set(mode="POSE")
    data.display_type = "STICK"
    # Body: head, eyes and a neck; hair as thin cylinders on the bones.
    head_mesh = sphere(f"{label}Head", HEAD_CENTRE, HEAD_RADIUS, mats["skin"], collection)
    for side in (-1, 1):
        eye = sphere(
            f"{label}Eye",
            HEAD_CENTRE + Vector((0.075 * side, -0.19, 0.0)),
            0.045,
            mats["eye"],
            collection,
        )
        parent_to_bone(eye, rig, "Head")
    parent_to_bone(head_mesh, rig, "Head")
    neck = cylinder(f"{label}Neck", 0.35, 0.07, mats["skin"], collection)
    neck.location = (0, 0, 1.55)
    neck.rotation_euler = (math.pi / 2, 0, 0)
    for name, _, _, count, length in CHAINS:
        mat = mats["ear"] if name.startswith("Ear") else mats["hair"]
        radius = 0.028 if name.startswith("Ear") else (0.02 if name in ("Ahoge", "Tail") else 0.014)
        for i in range(count):
            piece = cylinder(f"{label}{name}.{i}", length, radius, mat, collection)
            parent_to_bone(piece, rig, f"{name}.{i}", keep_world=False)
    return rig, collection


def add_rods(rig):
    bpy.context.view_layer.objects.active = rig
    for pb in rig.pose.bones:
        chains.set_selected(pb, pb.name.endswith(".0"))
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    for rod in rig.kodawari_hair.rods:
        rod.stiffness = (
            0.9
            if rod.root_bone.startswith("Ear")
            else (0.35 if rod.root_bone.startswith("Tail") else 0.6)
        )
        rod.iterations = 6
        rod.damping = 1.5
        rod.radius = 0.012
    assert bpy.ops.kodawari.rod_collider_add(
        bone="Head", shape="SPHERE", radius=HEAD_RADIUS, offset=(0.0, 0.25, 0.0)
    ) == {"FINISHED"}


def curl(rig, name, axis_world, degrees):
    """Turns every joint of a chain by `degrees` about a world axis (a curl in that plane)."""
    for pb in rig.pose.bones:
        if pb.name.startswith(name + "."):
            local_axis = pb.bone.matrix_local.to_3x3().inverted() @ Vector(axis_world)
            pb.rotation_quaternion = Quaternion(local_axis.normalized(), math.radians(degrees))


def reset_pose(rig):
    for pb in rig.pose.bones:
        pb.rotation_quaternion = (1, 0, 0, 0)


def key_views(rig, scene):
    """The artist's keys, set with the add-on's own operators from four camera positions."""
    rods = {rod.root_bone.split(".")[0]: i for i, rod in enumerate(rig.kodawari_hair.rods)}
    keycam = bpy.data.objects.new("KeyCamera", bpy.data.cameras.new("KeyCamera"))
    scene.collection.objects.link(keycam)
    scene.camera = keycam
    views = {"front": (0, -5, 1.8), "right": (5, 0, 1.8), "back": (0, 5, 1.8), "left": (-5, 0, 1.8)}
    # Ahoge: always curled sideways on screen: about the view axis.
    ahoge_axis = {"front": (0, 1, 0), "right": (1, 0, 0), "back": (0, -1, 0), "left": (-1, 0, 0)}
    # Rabbit ears, three keyed views: spread from the front, swept back from the side, drooping from behind.
    ears = {
        "front": (("EarL", (0, 1, 0), -12), ("EarR", (0, 1, 0), 12)),
        "right": (("EarL", (1, 0, 0), -16), ("EarR", (1, 0, 0), -16)),
        "back": (("EarL", (0, 1, 0), -30), ("EarR", (0, 1, 0), 30)),
    }
    for view, location in views.items():
        keycam.location = location
        bpy.context.view_layer.update()
        reset_pose(rig)
        curl(rig, "Ahoge", ahoge_axis[view], 32)
        assert bpy.ops.kodawari.rod_key_view(source="CAMERA", rod_index=rods["Ahoge"]) == {
            "FINISHED"
        }
        if view in ears:
            for name, axis, degrees in ears[view]:
                curl(rig, name, axis, degrees)
                assert bpy.ops.kodawari.rod_key_view(source="CAMERA", rod_index=rods[name]) == {
                    "FINISHED"
                }
        if view == "front":
            # Bangs part away from the eyes when seen from the front.
            curl(rig, "BangL", (0, 1, 0), 26)
            curl(rig, "BangR", (0, 1, 0), -26)
            curl(rig, "BangM", (1, 0, 0), -28)
            for name in ("BangL", "BangM", "BangR"):
                assert bpy.ops.kodawari.rod_key_view(source="CAMERA", rod_index=rods[name]) == {
                    "FINISHED"
                }
    reset_pose(rig)
    bpy.data.objects.remove(keycam)


def animate(rigs, scene):
    """Head nods and turns; the camera orbits once (front at frame 25)."""
    for rig in rigs:
        head = rig.pose.bones["Head"]
        head.rotation_mode = "XYZ"
        frames = np.arange(1, 101, dtype=np.float32)
        t = frames / 24.0
        rotation = np.stack(
            [
                0.25 * np.sin(2 * math.pi * 0.7 * t),
                0.2 * np.sin(2 * math.pi * 0.45 * t),
                0.3 * np.sin(2 * math.pi * 0.3 * t),
            ],
            axis=1,
        )
        action = fcurves.ensure_action(rig, f"{rig.name}Motion")
        fcurves.write_channels(
            action, rig, 'pose.bones["Head"].rotation_euler', frames, rotation, group="Head"
        )
        bob = np.stack(
            [
                0.04 * np.sin(2 * math.pi * 0.9 * t),
                np.zeros_like(t),
                0.03 * np.sin(2 * math.pi * 1.3 * t),
            ],
            axis=1,
        )
        fcurves.write_channels(
            action, rig, 'pose.bones["Head"].location', frames, bob, group="Head"
        )
    pivot = bpy.data.objects.new("Orbit", None)
    scene.collection.objects.link(pivot)
    pivot.location = (0, 0, 1.8)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    scene.collection.objects.link(camera)
    camera.data.lens = 85
    camera.parent = pivot
    camera.location = (0, -4.2, 0.12)
    camera.rotation_euler = (math.radians(90), 0, 0)
    frames = np.array([1, 101], dtype=np.float32)
    angles = (frames - FRAMES["front"]) / 96.0 * 2 * math.pi
    fcurves.write_channels(
        fcurves.ensure_action(pivot, "Orbit"),
        pivot,
        "rotation_euler",
        frames,
        np.stack([np.zeros(2), np.zeros(2), angles], axis=1),
    )
    scene.camera = camera
    return camera


def setup_render(scene):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 12
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = TILE
    scene.render.resolution_percentage = 100
    scene.render.use_lock_interface = True
    world = bpy.data.worlds.new("World")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.6, 0.68, 1)
    scene.world = world
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(40), math.radians(10), math.radians(30))
    scene.collection.objects.link(sun)


def render_tile(scene, path):
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(TILE[1], TILE[0], 4)
    bpy.data.images.remove(image)
    os.remove(path)
    return pixels


# Sheet labels, drawn with NumPy (no fonts or PIL inside Blender): a 5x7 pixel font
# (g, p, y reach two rows below the baseline) for the few letters the labels use, scaled up.
ROW_LABELS = ("plain physics", "view-dependent")
GLYPHS = {
    "a": ("     ", "     ", " ### ", "    #", " ####", "#   #", " ####"),
    "b": ("#    ", "#    ", "#### ", "#   #", "#   #", "#   #", "#### "),
    "c": ("     ", "     ", " ####", "#    ", "#    ", "#    ", " ####"),
    "d": ("    #", "    #", " ####", "#   #", "#   #", "#   #", " ####"),
    "e": ("     ", "     ", " ### ", "#   #", "#####", "#    ", " ### "),
    "f": ("  ## ", " #   ", "#### ", " #   ", " #   ", " #   ", " #   "),
    "g": ("     ", "     ", " ####", "#   #", "#   #", "#   #", " ####", "    #", " ### "),
    "h": ("#    ", "#    ", "#### ", "#   #", "#   #", "#   #", "#   #"),
    "i": ("  #  ", "     ", " ##  ", "  #  ", "  #  ", "  #  ", " ### "),
    "k": ("#    ", "#    ", "#  # ", "# #  ", "##   ", "# #  ", "#  # "),
    "l": (" ##  ", "  #  ", "  #  ", "  #  ", "  #  ", "  #  ", " ### "),
    "n": ("     ", "     ", "#### ", "#   #", "#   #", "#   #", "#   #"),
    "o": ("     ", "     ", " ### ", "#   #", "#   #", "#   #", " ### "),
    "p": ("     ", "     ", "#### ", "#   #", "#   #", "#   #", "#### ", "#    ", "#    "),
    "r": ("     ", "     ", "# ###", "##   ", "#    ", "#    ", "#    "),
    "s": ("     ", "     ", " ####", "#    ", " ### ", "    #", "#### "),
    "t": (" #   ", " #   ", "#### ", " #   ", " #   ", " #  #", "  ## "),
    "v": ("     ", "     ", "#   #", "#   #", "#   #", " # # ", "  #  "),
    "w": ("     ", "     ", "#   #", "#   #", "# # #", "# # #", " # # "),
    "y": ("     ", "     ", "#   #", "#   #", "#   #", "#   #", " ####", "    #", " ### "),
    "-": ("     ", "     ", "     ", "#### ", "     ", "     ", "     "),
    " ": ("     ",) * 7,
}


def text_mask(text, scale):
    """Boolean (9 * scale, 6 * scale * len(text)) mask of `text`, one column of space per glyph."""
    columns = [
        np.array([[c == "#" for c in row + " "] for row in (GLYPHS[ch] + ("     ",) * 2)[:9]])
        for ch in text.lower()
    ]
    mask = np.concatenate(columns, axis=1)
    return np.kron(mask, np.ones((scale, scale), dtype=bool))


def draw_text(image, text, top, left, scale=3, color=(0.05, 0.05, 0.08)):
    """Draws `text` into a top-row-first RGBA float image, on a light plate for contrast."""
    mask = text_mask(text, scale)
    pad = scale * 2
    h, w = mask.shape
    plate = image[top : top + h + 2 * pad, left : left + w + 2 * pad]
    plate[..., :3] = 0.5 * plate[..., :3] + 0.5 * 0.95
    region = image[top + pad : top + pad + h, left + pad : left + pad + w]
    region[mask, :3] = color


def labelled_sheet(rows, row_labels, column_labels, header=44):
    """Stacks the rows (top first) under a header band naming the columns; names each row."""
    width = rows[0].shape[1]
    band = np.ones((header, width, 4), dtype=np.float32)
    band[..., :3] = 0.85
    sheet = np.concatenate([band] + list(rows), axis=0)
    for c, label in enumerate(column_labels):
        text_width = text_mask(label, 3).shape[1] + 12
        draw_text(sheet, label, 4, c * TILE[0] + (TILE[0] - text_width) // 2)
    for r, label in enumerate(row_labels):
        draw_text(sheet, label, header + r * TILE[1] + 8, 8)
    return sheet


def swing_demo(scene, mats, hidden):
    """A third character whose head lunges forward and back, then holds still: its 18-bone
    ponytail swings and comes to rest. Rendered live (no bake) from the side, every other
    frame, into out/hair_swing.gif (ffmpeg) and the frames' strip out/hair_swing.png."""
    for collection in hidden:
        collection.hide_render = True
    rig, collection = build_character("Swing", mats)
    add_rods(rig)
    head = rig.pose.bones["Head"]
    head.rotation_mode = "XYZ"
    for frame, y, tilt in ((1, 0.0, 0.0), (9, -0.35, 0.35), (18, 0.08, -0.15), (26, 0.0, 0.0)):
        head.location = (0.0, y, 0.0)
        head.rotation_euler = (tilt, 0.0, 0.0)
        head.keyframe_insert("location", frame=frame)
        head.keyframe_insert("rotation_euler", frame=frame)
    bpy.ops.object.mode_set(mode="OBJECT")
    rig.hide_render = True
    camera = bpy.data.objects.new("SideCamera", bpy.data.cameras.new("SideCamera"))
    scene.collection.objects.link(camera)
    camera.data.type = "ORTHO"
    camera.data.ortho_scale = 1.6
    camera.location = (4.0, 0.05, 1.55)
    camera.rotation_euler = (math.radians(90), 0, math.radians(90))
    scene.camera = camera
    scene.render.engine = "BLENDER_WORKBENCH"
    if scene.world is None:
        scene.world = bpy.data.worlds.new("World")
    scene.world.color = (0.55, 0.6, 0.68)
    scene.display.shading.light = "STUDIO"
    scene.display.shading.color_type = "MATERIAL"
    scene.render.resolution_x, scene.render.resolution_y = 320, 360
    frames = []
    for frame in SWING_FRAMES:
        scene.frame_set(frame)  # the live handler simulates every frame in order
        path = os.path.join(OUT, f"_swing_{len(frames):03d}.png")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        frames.append(path)
    gif = os.path.join(OUT, "hair_swing.gif")
    try:
        subprocess.run(
            [
                "ffmpeg",
                "-y",
                "-loglevel",
                "error",
                "-framerate",
                "12",
                "-i",
                os.path.join(OUT, "_swing_%03d.png"),
                "-vf",
                "split[a][b];[a]palettegen=max_colors=64[p];[b][p]paletteuse",
                gif,
            ],
            check=True,
        )
        print(f"wrote {gif}")
    except (OSError, subprocess.CalledProcessError) as exc:
        print(f"no GIF ({exc}): the frames are out/_swing_*.png")
        return
    # A strip of six moments (0, 0.5, 1, 2, 3.5, 6 s) for pages that show no GIF.
    picks = [0, 6, 12, 24, 42, len(frames) - 1]
    tiles = []
    for index in picks:
        image = bpy.data.images.load(frames[index])
        tiles.append(np.array(image.pixels[:], dtype=np.float32).reshape(360, 320, 4))
        bpy.data.images.remove(image)
    strip = np.concatenate(tiles, axis=1)
    image = bpy.data.images.new("hair_swing", strip.shape[1], strip.shape[0])
    image.pixels[:] = strip.ravel()
    image.filepath_raw = os.path.join(OUT, "hair_swing.png")
    image.file_format = "PNG"
    image.save()
    for path in frames:
        os.remove(path)


def main():
    os.makedirs(OUT, exist_ok=True)
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, 100
    scene.render.fps = 24
    mats = {
        "skin": material("Skin", (0.9, 0.72, 0.62)),
        "eye": material("Eye", (0.02, 0.02, 0.03)),
        "hair": material("Hair", (0.25, 0.12, 0.4)),
        "ear": material("Ear", (0.95, 0.93, 0.92)),
    }
    plain, plain_collection = build_character("Plain", mats)
    kodawari, kodawari_collection = build_character("Kodawari", mats)
    add_rods(plain)
    add_rods(kodawari)
    key_views(kodawari, scene)
    animate((plain, kodawari), scene)
    setup_render(scene)
    # Bake both (bake equals live): the renders then need no handler.
    for rig in (plain, kodawari):
        bpy.context.view_layer.objects.active = rig
        assert bpy.ops.kodawari.rod_bake(frame_start=1, frame_end=100) == {"FINISHED"}
    bpy.ops.object.mode_set(mode="OBJECT")
    for rig in (plain, kodawari):
        rig.hide_render = True
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "hair.blend"))
    rows = []
    for collection, other in (
        (plain_collection, kodawari_collection),
        (kodawari_collection, plain_collection),
    ):
        collection.hide_render, other.hide_render = False, True
        row = []
        for view, frame in FRAMES.items():
            scene.frame_set(frame)
            tile = render_tile(scene, os.path.join(OUT, f"_hair_{collection.name}_{view}.png"))
            row.append(tile[::-1])  # top row first, like the sheet is drawn below
            print(f"rendered {collection.name} {view} (frame {frame})")
        rows.append(np.concatenate(row, axis=1))
    sheet = labelled_sheet(rows, ROW_LABELS, list(FRAMES))
    height, width = sheet.shape[:2]
    image = bpy.data.images.new("hair_sheet", width, height)
    image.pixels[:] = sheet[::-1].ravel()  # Blender images start at the bottom
    image.filepath_raw = os.path.join(OUT, "hair_sheet.png")
    image.file_format = "PNG"
    image.save()
    print(f"wrote {os.path.join(OUT, 'hair.blend')} and {image.filepath_raw}")
    swing_demo(scene, mats, (plain_collection, kodawari_collection))


main()
