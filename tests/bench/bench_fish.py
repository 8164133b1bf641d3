"""Fish swim benchmark (run in Blender 3.4 by tools/run_bench.sh; prints figures, never fails on time).

1. A 1 M-vertex fish per frame: our live evaluation against Blender's Curve
   modifier bending the same mesh along a curve whose points move every frame
   (the built-in way to make a fish swim), in this one process.
2. A 100 k-vertex fish (with fins): milliseconds per frame.

"ours (kernel + write)" = body and fin axes, native FFD deform into a preallocated
array and one write into the shape key; "ours (frame)" = a whole scene.frame_set,
i.e. that plus Blender re-evaluating the mesh (copy-on-write, shape key mix), which
the Curve modifier pays too ("Blender's own mesh update" measures that floor).
"""

import os
import sys
import time

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "blend_samples"))
import fish_shapes

FRAMES = 8


def _fish(rings, segments, fins=True):
    obj = fish_shapes.build_fish("tuna", rings=rings, segments=segments, fin_rows=8 if fins else 2)
    if not fins:
        for group in list(obj.vertex_groups):
            obj.vertex_groups.remove(group)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    bpy.ops.kodawari.swim_add(head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    for group in obj.vertex_groups:
        bpy.ops.kodawari.swim_fin_add(
            vertex_group=group.name, kind=group.name.split("_")[1].upper()
        )
    obj.select_set(False)
    return obj


def _time_ours(obj):
    from kodawari.fish import runtime

    scene = bpy.context.scene
    runtime.evaluate(obj, scene, 1)  # warm
    kernel = []
    for frame in range(2, 2 + FRAMES):
        t = time.perf_counter()
        runtime.evaluate(obj, scene, frame)
        kernel.append(time.perf_counter() - t)
    full = []
    for frame in range(2, 2 + FRAMES):
        t = time.perf_counter()
        scene.frame_set(frame)
        bpy.context.evaluated_depsgraph_get()
        full.append(time.perf_counter() - t)
    return float(np.median(kernel)), float(np.median(full))


def _time_blender_floor(obj):
    """Blender re-evaluating the same mesh after a tag, with no deformer work at all:
    the floor any per-frame deformer (ours or the Curve modifier) pays on top."""
    obj.kodawari_swim.enabled = False
    depsgraph = bpy.context.evaluated_depsgraph_get()
    times = []
    for _ in range(FRAMES):
        obj.data.update_tag()
        t = time.perf_counter()
        depsgraph.update()
        times.append(time.perf_counter() - t)
    obj.kodawari_swim.enabled = True
    return float(np.median(times))


def _time_curve_modifier(obj):
    """A copy of the mesh bent by Blender's Curve modifier along a 16-point curve
    whose points move each frame (what a user would animate without Kodawari)."""
    mesh = obj.data.copy()
    copy = bpy.data.objects.new("curve_fish", mesh)
    bpy.context.scene.collection.objects.link(copy)
    if copy.data.shape_keys is not None:
        copy.shape_key_clear()
    curve_data = bpy.data.curves.new("spine", "CURVE")
    curve_data.dimensions = "3D"
    spline = curve_data.splines.new("POLY")
    spline.points.add(15)
    xs = np.linspace(-0.6, 0.6, 16)
    curve = bpy.data.objects.new("spine", curve_data)
    bpy.context.scene.collection.objects.link(curve)
    modifier = copy.modifiers.new("Curve", "CURVE")
    modifier.object = curve
    modifier.deform_axis = "POS_X"
    obj.kodawari_swim.enabled = False
    obj.hide_viewport = True
    depsgraph = bpy.context.evaluated_depsgraph_get()
    times = []
    for frame in range(FRAMES + 1):
        ys = 0.08 * np.sin(2 * np.pi * (xs + 0.1 * frame))
        co = np.stack([xs, ys, np.zeros(16), np.ones(16)], axis=1).astype(np.float32)
        spline.points.foreach_set("co", co.reshape(-1))
        curve_data.update_tag()
        t = time.perf_counter()
        depsgraph.update()
        _ = copy.evaluated_get(depsgraph).data.vertices[0].co  # the modifier has run
        if frame:
            times.append(time.perf_counter() - t)
    obj.hide_viewport = False
    obj.kodawari_swim.enabled = True
    copy.hide_viewport = True
    return float(np.median(times))


def main():
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    scene.render.fps = 24

    t = time.perf_counter()
    big = _fish(rings=1000, segments=1000, fins=True)
    n_big = len(big.data.vertices)
    print(f"built and bound a {n_big:,}-vertex fish in {time.perf_counter() - t:.1f} s")
    kernel, full = _time_ours(big)
    floor = _time_blender_floor(big)
    curve = _time_curve_modifier(big)
    print(
        f"1M fish, ours (kernel + write): {kernel * 1e3:8.1f} ms/frame  ({kernel / n_big * 1e9:6.1f} ns/vertex)"
    )
    print(f"1M fish, ours (frame):          {full * 1e3:8.1f} ms/frame")
    print(
        f"1M fish, Curve modifier:        {curve * 1e3:8.1f} ms/frame  ({curve / n_big * 1e9:6.1f} ns/vertex)"
    )
    print(f"ratio Curve modifier / ours (kernel + write): {curve / kernel:5.1f}x   (target >= 10x)")
    print(f"1M fish, Blender's own mesh update (no deformer): {floor * 1e3:6.1f} ms/frame")
    print(f"ratio Curve modifier / ours (frame):          {curve / full:5.1f}x")
    print(
        f"ratio (Curve modifier - floor) / ours (kernel + write): {(curve - floor) / kernel:5.1f}x"
    )
    bpy.data.objects.remove(big)

    small = _fish(rings=320, segments=310, fins=True)
    n_small = len(small.data.vertices)
    kernel, full = _time_ours(small)
    print(
        f"{n_small:,}-vertex fish, ours (kernel + write): {kernel * 1e3:6.2f} ms/frame (target < 10 ms)"
    )
    print(f"{n_small:,}-vertex fish, ours (frame):          {full * 1e3:6.2f} ms/frame")


main()
