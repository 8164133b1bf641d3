"""Gait demo (runs inside Blender with the add-on enabled; tools/run_demo.sh):
a Thoroughbred keyed 1.5 -> 17 -> 1.5 m/s walks, trots, canters and gallops; a small
dog with its own table runs up to a rotary gallop. Both are set up, baked and
reported with the add-on's own operators. Writes to $KODAWARI_OUT (default out/):
  horse.blend, horse_gaits.png (a rendered strip, one frame per gait),
  horse_gait_report.png/.json, dog_gait_report.png/.json;
and Blender's own Rigify wolf and horse metarigs (rigs nobody on the project made),
skinned with a simple mesh, set up and baked walk -> trot -> gallop with the same
operators: rigify_gaits.png (one row per animal) and rigify_gaits.gif."""

import math
import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))  # gait_samples
OUT = os.environ.get("KODAWARI_OUT", os.path.join(os.getcwd(), "out"))
FPS = 24


def material(name, color):
    mat = bpy.data.materials.new(name)
    mat.use_nodes = True
    bsdf = mat.node_tree.nodes.get("Principled BSDF")
    bsdf.inputs["Base Color"].default_value = color
    bsdf.inputs["Roughness"].default_value = 0.6
    return mat


def build_scene():
    import gait_samples as samples

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    scene.frame_start, scene.frame_end = 1, 30 * FPS

    ground = bpy.data.objects.new("Ground", bpy.data.meshes.new("Ground"))
    ground.data.from_pydata(
        [(-30, -400, 0), (30, -400, 0), (30, 30, 0), (-30, 30, 0)], [], [(0, 1, 2, 3)]
    )
    ground.data.materials.append(material("Turf", (0.32, 0.42, 0.22, 1)))
    scene.collection.objects.link(ground)

    horse, horse_body = samples.build_horse(scene)
    horse_body.data.materials.append(material("Bay", (0.12, 0.045, 0.018, 1)))
    dog, dog_body = samples.build_dog(scene)
    dog.location = (-3.0, 0.0, 0.0)
    dog_body.data.materials.append(material("Fawn", (0.45, 0.28, 0.12, 1)))

    # Horse: keyed speed through every gait (the user's way to direct the run).
    bpy.context.view_layer.objects.active = horse
    bpy.ops.kodawari.gait_setup()
    samples.key_speed(horse, [(1, 1.5), (48, 1.5), (360, 17.0), (672, 1.5), (720, 1.5)])
    # Dog: its own table (AUTO ends in the rotary gallop) and its own speed curve.
    bpy.context.view_layer.objects.active = dog
    bpy.ops.kodawari.gait_setup()
    samples.apply_dog_table(dog.kodawari_gait)
    samples.key_speed(dog, [(1, 0.6), (48, 0.6), (360, 6.5), (672, 0.6), (720, 0.6)])

    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.7, 0.9, 1)
    world.node_tree.nodes["Background"].inputs["Strength"].default_value = 0.8
    scene.world = world
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(50), 0, math.radians(30))
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 35
    camera.rotation_euler = (
        math.radians(88),
        0,
        math.radians(90),
    )  # looks along -X: runs to the left
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene, horse, dog


def bake(obj):
    bpy.context.view_layer.objects.active = obj
    t = time.perf_counter()
    result = bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=30 * FPS)
    print(f"  baked {obj.name}: {result} in {time.perf_counter() - t:.2f} s")


def render_tiles(scene, shots):
    """Render each (object, frame, label) side-on and paste them into one strip."""
    from kodawari.gait.font import draw_text
    from kodawari.gait.report import save_png

    scene.render.engine = "CYCLES"
    scene.cycles.device = "CPU"
    scene.cycles.samples = 12
    scene.cycles.use_denoising = False
    scene.render.resolution_x, scene.render.resolution_y = 480, 270
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    tiles = []
    for obj, frame, label, distance in shots:
        scene.frame_set(frame)
        body = obj.matrix_world @ obj.pose.bones[obj.kodawari_gait.body_bone].head
        scene.camera.location = (body.x + distance, body.y - 0.2 * distance, body.z * 0.75)
        path = os.path.join(OUT, "_tile.png")
        scene.render.filepath = path
        bpy.ops.render.render(write_still=True)
        image = bpy.data.images.load(path)
        pixels = np.empty(480 * 270 * 4, dtype=np.float32)
        image.pixels.foreach_get(pixels)
        bpy.data.images.remove(image)
        os.remove(path)
        tile = pixels.reshape(270, 480, 4)[::-1].copy()  # row 0 at the top
        draw_text(tile, 10, 10, label, (1, 1, 1, 1), 3)
        tiles.append(tile)
    strip = np.concatenate(tiles, axis=1)
    save_png(strip, os.path.join(OUT, "horse_gaits.png"))


def rigify_scene():
    """The Rigify wolf and horse metarigs side by side, each skinned, set up by name and
    keyed walk -> trot -> gallop in its own Froude-scaled speed bands."""
    import gait_samples as samples

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps, scene.render.fps_base = FPS, 1.0
    ground = bpy.data.objects.new("Ground", bpy.data.meshes.new("Ground"))
    ground.data.from_pydata(
        [(-20, -300, 0), (20, -300, 0), (20, 20, 0), (-20, 20, 0)], [], [(0, 1, 2, 3)]
    )
    turf = material("Turf", (0.32, 0.42, 0.22, 1))
    turf.diffuse_color = (0.32, 0.42, 0.22, 1)
    ground.data.materials.append(turf)
    scene.collection.objects.link(ground)
    animals = []
    for name, x, color, radius in (
        ("wolf", 0.0, (0.35, 0.33, 0.3, 1), 0.14),
        ("horse", -3.0, (0.12, 0.045, 0.018, 1), 0.3),
    ):
        rig = samples.rigify_metarig(scene, name)
        rig.location.x = x
        bpy.context.view_layer.objects.active = rig
        bpy.ops.kodawari.gait_setup()
        s = rig.kodawari_gait
        legs = {b.name for leg in s.legs for b in leg.bones}
        trunk = {
            b.name for b in rig.data.bones if b.name.split(".")[0] in ("spine", "shoulder", "thigh")
        }
        body = samples.skin_armature(rig, scene, legs | trunk, radius)
        coat = material(name.capitalize(), color)
        coat.diffuse_color = color  # what Workbench shows
        body.data.materials.append(coat)
        top = {e.name: e.speed_max for e in s.table}
        walk, trot, gallop = (
            0.7 * top["WALK"],
            0.5 * (top["WALK"] + top["TROT"]),
            0.5 * (top["CANTER"] + top["GALLOP"]),
        )
        s.acceleration = 6.0
        samples.key_speed(
            rig,
            [
                (1, walk),
                (3 * FPS, walk),
                (4 * FPS, trot),
                (7 * FPS, trot),
                (9 * FPS, gallop),
                (12 * FPS, gallop),
            ],
        )
        bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=12 * FPS)
        animals.append((rig, name))
    world = bpy.data.worlds.new("Sky")
    world.use_nodes = True
    world.node_tree.nodes["Background"].inputs["Color"].default_value = (0.55, 0.7, 0.9, 1)
    scene.world = world
    sun = bpy.data.objects.new("Sun", bpy.data.lights.new("Sun", "SUN"))
    sun.data.energy = 3.0
    sun.rotation_euler = (math.radians(50), 0, math.radians(30))
    scene.collection.objects.link(sun)
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    camera.data.lens = 35
    camera.rotation_euler = (math.radians(88), 0, math.radians(90))
    scene.collection.objects.link(camera)
    scene.camera = camera
    return scene, animals


def render_frame(scene, rig, frame, distance, size=(400, 240)):
    """One side-on Workbench render following the animal (Workbench: a second a frame on
    a busy CPU where Cycles takes a minute): (H, W, 4) float, row 0 at the top."""
    scene.render.engine = "BLENDER_WORKBENCH"
    shading = scene.display.shading
    shading.light, shading.color_type = "STUDIO", "MATERIAL"
    shading.show_shadows, shading.show_cavity = True, True
    scene.render.resolution_x, scene.render.resolution_y = size
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.frame_set(frame)
    s = rig.kodawari_gait
    roots = [rig.matrix_world @ rig.pose.bones[leg.bones[0].name].head for leg in s.legs]
    centre = sum(roots, roots[0] * 0) / 4
    scene.camera.location = (centre.x + distance, centre.y - 0.1 * distance, centre.z * 1.1)
    for other in scene.objects:  # only this animal in the picture
        if other.type in ("ARMATURE", "MESH") and other.name != "Ground":
            other.hide_render = other is not rig and other.parent is not rig
    path = os.path.join(OUT, "_frame.png")
    scene.render.filepath = path
    bpy.ops.render.render(write_still=True)
    image = bpy.data.images.load(path)
    pixels = np.empty(size[0] * size[1] * 4, dtype=np.float32)
    image.pixels.foreach_get(pixels)
    bpy.data.images.remove(image)
    os.remove(path)
    return pixels.reshape(size[1], size[0], 4)[::-1].copy()


def rigify_demo():
    from kodawari.gait import metrics, runtime
    from kodawari.gait.font import draw_text
    from kodawari.gait.report import save_png

    scene, animals = rigify_scene()
    rows, gif = [], []
    for rig, name in animals:
        distance = 3.0 if name == "wolf" else 5.0
        gaits = runtime.last_bake(rig)["result"]["gait"]
        tiles = []
        for label, gait in (("WALK", 0), ("TROT", 1), ("GALLOP", 3)):
            frames = np.flatnonzero(gaits == gait)
            frame = int(frames[len(frames) * 2 // 3]) + 1
            tile = render_frame(scene, rig, frame, distance)
            draw_text(tile, 8, 8, f"RIGIFY {name.upper()} {label}", (1, 1, 1, 1), 2)
            tiles.append(tile)
            # an animated loop: a second of each gait at 12 frames per second
            for f in range(frame - FPS // 2, frame + FPS // 2, 2):
                clip = render_frame(scene, rig, f, distance, size=(320, 192))
                draw_text(clip, 6, 6, f"RIGIFY {name.upper()} {label}", (1, 1, 1, 1), 2)
                gif.append(clip)
        rows.append(np.concatenate(tiles, axis=1))
        print(f"  {name}: gaits {[metrics.GAITS[g] for g, _, _ in metrics.segments(gaits)]}")
    save_png(np.concatenate(rows, axis=0), os.path.join(OUT, "rigify_gaits.png"))
    frames_dir = os.path.join(OUT, "_gif")
    os.makedirs(frames_dir, exist_ok=True)
    for i, clip in enumerate(gif):
        save_png(clip, os.path.join(frames_dir, f"{i:04d}.png"))
    import shutil
    import subprocess

    if shutil.which("ffmpeg"):
        subprocess.run(
            [
                "ffmpeg",
                "-y",
                "-loglevel",
                "error",
                "-framerate",
                "12",
                "-i",
                os.path.join(frames_dir, "%04d.png"),
                "-vf",
                "split[a][b];[a]palettegen[p];[b][p]paletteuse",
                "-loop",
                "0",
                os.path.join(OUT, "rigify_gaits.gif"),
            ],
            check=True,
        )
    shutil.rmtree(frames_dir)
    print("  wrote", os.path.join(OUT, "rigify_gaits.png"), "and rigify_gaits.gif")


def main():
    os.makedirs(OUT, exist_ok=True)
    scene, horse, dog = build_scene()
    bake(horse)
    bake(dog)
    from kodawari.gait import metrics, runtime

    shots = []
    for obj, distance in ((horse, 6.0), (dog, 2.4)):
        gaits = runtime.last_bake(obj)["result"]["gait"]
        seen = set()
        for g, lo, hi in metrics.segments(gaits):
            if g in seen or (obj is dog and metrics.GAITS[g] != "GALLOP_ROTARY"):
                continue
            seen.add(g)
            label = metrics.GAITS[g].replace("GALLOP_ROTARY", "ROTARY GALLOP")
            shots.append((obj, int((lo + hi) / 2) + 1, f"{obj.name.upper()} {label}", distance))
    for obj, name in ((horse, "horse"), (dog, "dog")):
        bpy.context.view_layer.objects.active = obj
        bpy.ops.kodawari.gait_report(filepath=os.path.join(OUT, f"{name}_gait_report.png"))
    blend = os.path.join(OUT, "horse.blend")
    for stale in (blend, blend + "1"):  # no .blend1 backups in out/
        if os.path.exists(stale):
            os.remove(stale)
    bpy.ops.wm.save_as_mainfile(filepath=blend)
    t = time.perf_counter()
    render_tiles(scene, shots)
    print(f"  rendered {len(shots)} tiles in {time.perf_counter() - t:.1f} s")
    for name in (
        "horse.blend",
        "horse_gaits.png",
        "horse_gait_report.png",
        "horse_gait_report.json",
        "dog_gait_report.png",
        "dog_gait_report.json",
    ):
        print("  wrote", os.path.join(OUT, name))


try:
    if os.environ.get("KODAWARI_GAIT_DEMO", "all") in ("all", "sample"):
        main()
    if os.environ.get("KODAWARI_GAIT_DEMO", "all") in ("all", "rigify"):
        rigify_demo()
except Exception:
    import traceback

    traceback.print_exc()
    sys.exit(1)
