"""A live fish frame early and late in the timeline (run by tools/run_bench.sh in every
Blender; prints figures, never fails on time; writes out/bench.json -> fish_live).

A ~25 k-vertex tuna with fins, swimming live, its frequency keyframed (as a user animates
it). Whole frame as a viewport gets it (`scene.frame_set`, evaluation of what the handler
tagged, the evaluated normals read) at frames 10.. and at frames 10,000..; the two timed
interleaved round by round in one process. A frame's cost should not depend on its number.
"""

import os
import sys
import time

import bpy

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib
import fish_shapes

print = benchlib.say  # each line at once, also through a pipe

FRAMES = 8
STARTS = {"frame_10": 10, "frame_10000": 10_000}


def build(scene):
    obj = fish_shapes.build_fish("tuna", rings=160, segments=150, fin_rows=6)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    assert bpy.ops.kodawari.swim_add(head_axis="POS_X", preset="CARANGIFORM", frequency=2.0) == {
        "FINISHED"
    }
    for group in obj.vertex_groups:
        bpy.ops.kodawari.swim_fin_add(
            vertex_group=group.name, kind=group.name.split("_")[1].upper()
        )
    obj.select_set(False)
    settings = obj.kodawari_swim
    for frame, frequency in ((1, 1.5), (200, 2.5)):
        settings.frequency = frequency
        obj.keyframe_insert("kodawari_swim.frequency", frame=frame)
    return obj


def whole_frame(scene, obj, frame):
    scene.frame_set(frame)
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    mesh = obj.evaluated_get(depsgraph).data
    return tuple(mesh.vertices[0].normal) + tuple(mesh.vertices[len(mesh.vertices) - 1].co)


def player(scene, obj, first):
    def play(_round):
        whole_frame(scene, obj, first - 1)
        seconds = []
        for frame in range(first, first + FRAMES):
            start = time.perf_counter()
            whole_frame(scene, obj, frame)
            seconds.append(time.perf_counter() - start)
        return seconds

    return play


def main():
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 1, 20_000
    obj = build(scene)
    count = len(obj.data.vertices)
    rows = benchlib.Rounds().run(
        {name: player(scene, obj, first) for name, first in STARTS.items()}
    )
    peak = benchlib.peak_rss_mb()
    early, late = rows["frame_10"], rows["frame_10000"]
    print(
        f"=== live fish frame, {count:,} vertices with fins, frequency keyframed ({benchlib.blender_label()}): "
        f"ms per whole frame, min / median of {benchlib.ROUNDS} rounds of {FRAMES} frames; process peak {peak:.0f} MB"
    )
    for name in STARTS:
        print(f"    {name:12s} {benchlib.fmt_ms(rows[name])}  load {rows[name]['load']:4.1f}")
    print(
        f"    frame 10,000 / frame 10: {late['ms_median'] / early['ms_median']:5.2f}x (min {late['ms_min'] / early['ms_min']:5.2f}x)"
        "  (target 1.0x)"
    )
    for row in rows.values():
        row["vertices"] = count
        row["process_peak_rss_mb"] = round(peak, 1)
    benchlib.record("fish_live", rows)


main()
