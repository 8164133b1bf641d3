"""Fish swim demo: seven procedural fish, one per swimming preset, built and set up
with the add-on's own operators (the dolphin then baked to out/dolphin_swim.pc2
and a Mesh Cache modifier); saves out/fish.blend and renders
out/fish_sheet.png, a contact sheet with one row per fish, each labelled with
its preset — tuna (thunniform), tuna (carangiform), eel (anguilliform), boxfish
(ostraciiform), filefish (balistiform), pufferfish (labriform), dolphin
(cetacean) — and eight columns: four frames a quarter tail beat apart seen from
above (tilted 30 degrees toward the viewer), then the same four frames seen from
the side; and out/fish_<preset>.gif, one looping tail beat of each seen from
above (12 frames, made from the rendered frames with Debian's ffmpeg).
Runs in Blender 3.4 via tools/run_demo.sh.
"""

import math
import os
import shutil
import subprocess
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import fish_shapes

OUT = os.environ.get(
    "KODAWARI_OUT", os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "out")
)
TILE = (240, 136)
FRAMES = (1, 4, 7, 10)  # a quarter beat apart at 2 Hz, 24 fps
BEAT = range(1, 13)  # one whole beat at 2 Hz, 24 fps: the animated pictures loop
FONT = "/usr/share/fonts/truetype/dejavu/DejaVuSans-Bold.ttf"

FISH = (
    # kind, preset, colour body, colour fins, frequency
    ("tuna", "THUNNIFORM", (0.08, 0.12, 0.3), (0.75, 0.6, 0.15), 2.0),
    ("tuna", "CARANGIFORM", (0.25, 0.3, 0.32), (0.55, 0.5, 0.3), 2.0),
    ("eel", "ANGUILLIFORM", (0.18, 0.16, 0.08), (0.35, 0.3, 0.15), 2.0),
    ("boxfish", "OSTRACIIFORM", (0.8, 0.65, 0.1), (0.9, 0.85, 0.5), 2.0),
    ("filefish", "BALISTIFORM", (0.35, 0.45, 0.2), (0.6, 0.7, 0.4), 2.0),
    ("pufferfish", "LABRIFORM", (0.6, 0.55, 0.4), (0.85, 0.8, 0.6), 2.0),
    ("dolphin", "CETACEAN", (0.35, 0.38, 0.45), (0.3, 0.33, 0.4), 2.0),
)

FIN_KIND = {
    "fin_dorsal": "DORSAL",
    "fin_anal": "ANAL",
    "fin_pectoral": "PECTORAL",
    "fin_caudal": "CAUDAL",
}


def material(name, colour):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = (*colour, 1.0)
    bsdf.inputs["Roughness"].default_value = 0.45
    return mat


def build_scene():
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 1, 48
    fish = []
    for i, (kind, preset, body_colour, fin_colour, frequency) in enumerate(FISH):
        col, row = i % 3, i // 3
        # Diagonal rows: separated both from above (y) and from the side (z).
        location = (col * 1.3 - 1.3, -row * 0.75, -row * 0.6)
        obj = fish_shapes.build_fish(
            kind,
            location=location,
            materials=(material(kind + "_body", body_colour), material(kind + "_fins", fin_colour)),
        )
        bpy.context.view_layer.objects.active = obj
        obj.select_set(True)
        bpy.ops.kodawari.swim_add(head_axis="AUTO", preset=preset, frequency=frequency)
        for group in obj.vertex_groups:
            bpy.ops.kodawari.swim_fin_add(vertex_group=group.name, kind=FIN_KIND[group.name])
        obj.select_set(False)
        fish.append(obj)
    return scene, fish


def add_view(scene, name, rotation, scale):
    cam_data = bpy.data.cameras.new(name)
    cam_data.type = "ORTHO"
    cam_data.ortho_scale = scale
    cam = bpy.data.objects.new(name, cam_data)
    cam.rotation_euler = rotation
    scene.collection.objects.link(cam)
    return cam


def setup_render(scene):
    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 12
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = TILE
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    world = bpy.data.worlds.new("water")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.25, 0.42, 0.55, 1.0)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.6
    scene.world = world
    sun = bpy.data.objects.new("sun", bpy.data.lights.new("sun", "SUN"))
    sun.data.energy = 4.0
    sun.rotation_euler = (math.radians(30), math.radians(-25), math.radians(15))
    scene.collection.objects.link(sun)
    # "Above" is tilted 30 degrees toward the viewer so vertical fins (caudal, dorsal) show too.
    top = add_view(scene, "top", (math.radians(30), 0.0, 0.0), 1.45)
    side = add_view(scene, "side", (math.radians(90), 0.0, 0.0), 1.45)
    return top, side


def aim(top, side, obj):
    """Frame one fish: the top camera above it, the side camera beside it."""
    x, y, z = obj.location
    top.location = (
        x - 0.05,
        y - 5.0 * math.sin(math.radians(30)),
        z + 5.0 * math.cos(math.radians(30)),
    )
    side.location = (x - 0.05, y - 5.0, z)


def render_tile(scene, camera, frame, path):
    scene.camera = camera
    scene.frame_set(frame)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.array(image.pixels[:], dtype=np.float32).reshape(image.size[1], image.size[0], 4)
    bpy.data.images.remove(image)
    os.remove(path)
    return pixels


def _ffmpeg(*args):
    """Run Debian's ffmpeg quietly; False (and a note) when it is missing or fails."""
    if shutil.which("ffmpeg") is None:
        print("ffmpeg not found: skipping the labels and animated pictures")
        return False
    result = subprocess.run(["ffmpeg", "-y", "-loglevel", "error", *args], check=False)
    return result.returncode == 0


def label_sheet(path, labels, row_height):
    """Write each row's preset name into its top-left corner (ffmpeg drawtext)."""
    font = FONT if os.path.exists(FONT) else None
    filters = [
        "drawtext="
        + (f"fontfile={font}:" if font else "")
        + f"text='{text}':x=8:y={row * row_height + 6}:fontsize=15:fontcolor=white"
        ":box=1:boxcolor=black@0.55:boxborderw=4"
        for row, text in enumerate(labels)
    ]
    labelled = path.replace(".png", "_labelled.png")
    if _ffmpeg("-i", path, "-vf", ",".join(filters), labelled):
        os.replace(labelled, path)


def write_gif(frames, path, label):
    """An endlessly looping GIF of the rendered frames (12 fps), with its label."""
    folder = os.path.dirname(frames[0])
    pattern = os.path.join(folder, "_beat_%02d.png")
    for i, frame in enumerate(frames):
        os.replace(frame, pattern % i)
    font = FONT if os.path.exists(FONT) else None
    text = (
        "drawtext="
        + (f"fontfile={font}:" if font else "")
        + f"text='{label}':x=6:y=6:fontsize=13:fontcolor=white:box=1:boxcolor=black@0.55"
        ":boxborderw=3"
    )
    graph = f"{text},split[a][b];[a]palettegen=stats_mode=diff[p];[b][p]paletteuse=dither=bayer"
    _ffmpeg("-framerate", "12", "-i", pattern, "-filter_complex", graph, "-loop", "0", path)
    for i in range(len(frames)):
        os.remove(pattern % i)


def render_still(scene, camera, frame, path):
    scene.camera = camera
    scene.frame_set(frame)
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    return path


def main():
    os.makedirs(OUT, exist_ok=True)
    scene, fish = build_scene()
    top, side = setup_render(scene)
    width, height = TILE
    gap = 3
    columns = 2 * len(FRAMES)
    sheet = np.ones(
        ((height + gap) * len(fish), (width + gap) * columns + gap * 3, 4), dtype=np.float32
    )
    labels = []
    for row, obj in enumerate(fish):
        for other in fish:
            other.hide_render = other is not obj
        aim(top, side, obj)
        preset = obj.kodawari_swim.preset
        label = f"{presets_label(preset)} ({FISH[row][0]})"
        labels.append(label)
        # From above: one whole beat, rendered once, feeds both the sheet and the GIF.
        beat = [
            render_still(scene, top, frame, os.path.join(OUT, f"_top_{row}_{frame:02d}.png"))
            for frame in BEAT
        ]
        for view, camera in enumerate((top, side)):
            for c, frame in enumerate(FRAMES):
                if view == 0:
                    path = beat[frame - BEAT[0]]
                    image = bpy.data.images.load(path)
                    tile = np.array(image.pixels[:], dtype=np.float32).reshape(
                        image.size[1], image.size[0], 4
                    )
                    bpy.data.images.remove(image)
                else:
                    tile = render_tile(
                        scene, camera, frame, os.path.join(OUT, f"_tile_{row}_{view}_{c}.png")
                    )
                # Image rows run bottom-up: the first fish goes to the top of the sheet.
                y0 = sheet.shape[0] - (row + 1) * (height + gap)
                x0 = (view * len(FRAMES) + c) * (width + gap) + view * gap * 3
                sheet[y0 : y0 + height, x0 : x0 + width] = tile
        write_gif(beat, os.path.join(OUT, f"fish_{preset.lower()}.gif"), label)
    for obj in fish:
        obj.hide_render = False
    # The dolphin is baked to a PC2 point cache played by Blender's Mesh Cache modifier,
    # so it swims in out/fish.blend even where the add-on is not installed.
    dolphin = fish[-1]
    bpy.context.view_layer.objects.active = dolphin
    bpy.context.preferences.filepaths.save_version = 0  # no fish.blend1 beside it
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "fish.blend"))
    bpy.ops.kodawari.swim_bake(
        frame_start=scene.frame_start,
        frame_end=scene.frame_end,
        target="MESH_CACHE",
        filepath="//dolphin_swim.pc2",
    )
    scene.frame_set(1)
    bpy.ops.wm.save_as_mainfile(filepath=os.path.join(OUT, "fish.blend"))
    image = bpy.data.images.new("fish_sheet", sheet.shape[1], sheet.shape[0], alpha=True)
    image.pixels.foreach_set(sheet.reshape(-1))
    image.filepath_raw = os.path.join(OUT, "fish_sheet.png")
    image.file_format = "PNG"
    image.save()
    label_sheet(image.filepath_raw, labels, height + gap)
    print(f"wrote {os.path.join(OUT, 'fish.blend')}, {image.filepath_raw} and out/fish_*.gif")


def presets_label(preset):
    from kodawari.fish import presets

    return presets.LABELS[preset][0]


main()
