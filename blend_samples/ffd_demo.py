"""Foundation demo: a fish-like body bent by kodawari's control-axis FFD.

Runs inside Blender 3.4 after the add-on is enabled (bash tools/run_demo.sh):
builds a body mesh along +x, binds it once to a 6-point control axis, swims
the axis (a travelling wave growing toward the tail, lengths kept by
preserve_lengths_from_head), bakes one shape key per frame with keyframed
values, and writes out/ffd_demo.blend and a 2x2 sheet of rendered frames,
out/ffd_demo.png. The thin red tube above the body is the control curve.
"""

import os

import bpy
import numpy as np
from kodawari import bulk, fcurves, native

OUT = os.environ.get("KODAWARI_OUT", os.path.join(os.getcwd(), "out"))
FRAMES = 48
SHEET_FRAMES = (1, 7, 13, 19)
TILE = (480, 270)
AXIS_POINTS = 6
HEAD_X, AXIS_END_X, TAIL_X = -1.0, 1.2, 1.42  # the caudal fin reaches past the axis end


def body_mesh(name, rings=140, around=48):
    """A spindle body, a narrow peduncle and a tall thin caudal fin, along +x."""
    x = np.linspace(HEAD_X, TAIL_X, rings)
    s = (x - HEAD_X) / (1.0 - HEAD_X)  # 0 at the snout, 1 at the fin root
    body = 0.30 * np.sin(np.pi * np.clip(s, 0, 1) ** 0.75) ** 0.8
    height = np.where(s <= 1.0, np.maximum(body, 0.045), 0.045 + 0.9 * (s - 1.0) ** 0.9)
    width = np.where(s <= 1.0, 0.72 * np.maximum(body, 0.03), 0.012)
    height[0] = width[0] = 0.0  # close the snout in a point
    angle = np.linspace(0, 2 * np.pi, around, endpoint=False)
    co = np.empty((rings, around, 3), np.float32)
    co[..., 0] = x[:, None]
    co[..., 1] = width[:, None] * np.cos(angle)[None, :]
    co[..., 2] = height[:, None] * np.sin(angle)[None, :]
    faces = []
    for r in range(rings - 1):
        for a in range(around):
            b = (a + 1) % around
            faces.append(
                (r * around + a, r * around + b, (r + 1) * around + b, (r + 1) * around + a)
            )
    mesh = bpy.data.meshes.new(name)
    mesh.from_pydata(co.reshape(-1, 3).tolist(), [], faces)
    mesh.update()
    for polygon in mesh.polygons:
        polygon.use_smooth = True
    return mesh


def swim_axis(frame, rest, rest_lengths, rest_arc, kn):
    """Carangiform wave: amplitude grows toward the tail, one wavelength per body."""
    s = np.linspace(0, 1, AXIS_POINTS)
    phase = 2 * np.pi * frame / 24.0
    bent = rest.copy()
    bent[:, 1] += (0.04 + 0.30 * s * s) * np.sin(2 * np.pi * 0.9 * s - phase)
    return kn.preserve_lengths_from_head(bent, rest_lengths, arc_length=rest_arc)


def material(name, color, metallic=0.0, roughness=0.4):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes["Principled BSDF"]
    bsdf.inputs["Base Color"].default_value = (*color, 1.0)
    bsdf.inputs["Metallic"].default_value = metallic
    bsdf.inputs["Roughness"].default_value = roughness
    return mat


def striped_material():
    """Stripes across the body in its rest coordinates, so the bend is easy to read."""
    mat = material("fish_skin", (0.2, 0.45, 0.8), metallic=0.3)
    nodes, links = mat.node_tree.nodes, mat.node_tree.links
    coords = nodes.new("ShaderNodeTexCoord")
    wave = nodes.new("ShaderNodeTexWave")
    wave.inputs["Scale"].default_value = 4.0
    ramp = nodes.new("ShaderNodeValToRGB")
    ramp.color_ramp.elements[0].color = (0.05, 0.12, 0.3, 1)
    ramp.color_ramp.elements[1].color = (0.75, 0.85, 0.95, 1)
    links.new(coords.outputs["Generated"], wave.inputs["Vector"])
    links.new(wave.outputs["Fac"], ramp.inputs["Fac"])
    links.new(ramp.outputs["Color"], nodes["Principled BSDF"].inputs["Base Color"])
    return mat


def axis_curve(name, frames_points):
    """A NURBS curve of order 4 with endpoints (the FFD's clamped cubic B-spline),
    its points keyframed per frame, drawn as a thin tube above the body."""
    curve = bpy.data.curves.new(name, "CURVE")
    curve.dimensions = "3D"
    curve.bevel_depth = 0.012
    spline = curve.splines.new("NURBS")
    spline.points.add(AXIS_POINTS - 1)
    spline.order_u = 4
    spline.use_endpoint_u = True
    action = fcurves.ensure_action(curve, name + "_action")
    frames = np.arange(1, FRAMES + 1, dtype=np.float64)
    for i, point in enumerate(spline.points):
        values = np.column_stack([frames_points[:, i, :], np.ones(FRAMES)])
        point.co = values[0]
        fcurves.write_channels(
            action, curve, f"splines[0].points[{i}].co", frames, values, group="axis"
        )
    obj = bpy.data.objects.new(name, curve)
    obj.location.z = 0.45
    obj.visible_shadow = False
    obj.data.materials.append(material("axis_red", (0.85, 0.08, 0.05)))
    return obj


def bake_shape_keys(obj, binding, frames_points):
    """One shape key per frame; its value is keyed 1 on that frame, 0 on the neighbours."""
    obj.shape_key_add(name="Basis")
    out = np.empty((binding.count, 3), np.float32)
    key = obj.data.shape_keys
    action = fcurves.ensure_action(key, "ffd_swim")
    for frame in range(1, FRAMES + 1):
        binding.deform(frames_points[frame - 1], out)
        block = obj.shape_key_add(name=f"ffd_{frame:03d}", from_mix=False)
        bulk.set_shape_key_positions(block, out)
        frames = np.array([frame - 1, frame, frame + 1], np.float64)
        fcurve = fcurves.ensure_fcurve(
            action, key, f'key_blocks["{block.name}"].value', group="ffd"
        )
        fcurves.write_keys(fcurve, frames, np.array([0.0, 1.0, 0.0]))


def build_scene(kn):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, FRAMES

    mesh = body_mesh("ffd_body")
    body = bpy.data.objects.new("ffd_body", mesh)
    scene.collection.objects.link(body)
    mesh.materials.append(striped_material())

    rest = np.column_stack(
        [np.linspace(HEAD_X, AXIS_END_X, AXIS_POINTS), np.zeros(AXIS_POINTS), np.zeros(AXIS_POINTS)]
    )
    rest_lengths = np.linalg.norm(np.diff(rest, axis=0), axis=1)
    rest_arc = kn.curve_length(rest)
    binding = kn.ffd_bind(rest, bulk.vertex_positions(mesh))
    frames_points = np.stack(
        [swim_axis(f, rest, rest_lengths, rest_arc, kn) for f in range(1, FRAMES + 1)]
    )
    bake_shape_keys(body, binding, frames_points)
    scene.collection.objects.link(axis_curve("ffd_axis", frames_points))

    floor = bpy.data.meshes.new("floor")
    floor.from_pydata(
        [(-6, -6, -0.6), (6, -6, -0.6), (6, 6, -0.6), (-6, 6, -0.6)], [], [(0, 1, 2, 3)]
    )
    floor_obj = bpy.data.objects.new("floor", floor)
    floor.materials.append(material("sand", (0.75, 0.7, 0.6), roughness=0.9))
    scene.collection.objects.link(floor_obj)

    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (0.5, 0.2, 0.8)
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("camera", bpy.data.cameras.new("camera"))
    camera.location = (0.2, -1.1, 3.3)
    camera.rotation_euler = (0.3, 0.0, 0.0)
    camera.data.lens = 36
    scene.collection.objects.link(camera)
    scene.camera = camera
    world = bpy.data.worlds.new("world")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.7, 0.85, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world

    text = bpy.data.curves.new("label", "FONT")
    text.size = 0.18
    label = bpy.data.objects.new("label", text)
    label.location = (-1.3, -0.75, 0.0)
    label.rotation_euler = (0.3, 0.0, 0.0)
    label.visible_shadow = False
    label.data.materials.append(material("label", (0.02, 0.02, 0.02)))
    scene.collection.objects.link(label)
    return scene, label


def render_sheet(scene, label, path):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 12
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = TILE
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    width, height = TILE
    sheet = np.zeros((2 * height, 2 * width, 4), np.float32)
    for index, frame in enumerate(SHEET_FRAMES):
        scene.frame_set(frame)
        label.data.body = f"frame {frame}"
        tile_path = os.path.join(OUT, f"_ffd_tile_{index}.png")
        scene.render.filepath = tile_path
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(tile_path)
        pixels = np.empty(width * height * 4, np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        os.remove(tile_path)
        row, col = divmod(index, 2)
        # Blender images start at the bottom row: the first tiles go to the top half.
        sheet[(1 - row) * height : (2 - row) * height, col * width : (col + 1) * width] = (
            pixels.reshape(height, width, 4)
        )
    image = bpy.data.images.new("ffd_demo_sheet", 2 * width, 2 * height, alpha=True)
    image.pixels.foreach_set(sheet.reshape(-1))
    image.filepath_raw = path
    image.file_format = "PNG"
    image.save()
    bpy.data.images.remove(image)


def main():
    kn = native.module()
    os.makedirs(OUT, exist_ok=True)
    scene, label = build_scene(kn)
    blend_path = os.path.join(OUT, "ffd_demo.blend")
    png_path = os.path.join(OUT, "ffd_demo.png")
    render_sheet(scene, label, png_path)
    scene.frame_set(1)
    for stale in (blend_path, blend_path + "1"):  # no .blend1 backup of an earlier run
        if os.path.exists(stale):
            os.remove(stale)
    bpy.ops.wm.save_as_mainfile(filepath=blend_path)
    print(f"ffd demo wrote {blend_path} and {png_path}")


main()
