"""Find Fins at scale (issue 10 item 8; prints figures, never fails on time).

A smooth welded fish (blend_samples/smooth_fish.py) subdivided to about 2 M
vertices: the native fin search alone, and the whole Find Fins operator (search,
vertex groups, fin binding). Beside it, in the same run, the per-vertex ray cast
the previous finder did (BVHTree.ray_cast once per vertex), on a 1/20 sample and
scaled to the whole mesh.
"""

import os
import sys
import time

import bpy
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "blend_samples"))
import smooth_fish


def _ray_cast_baseline(obj, sample=20):
    from mathutils import Vector
    from mathutils.bvhtree import BVHTree

    mesh = obj.data
    t = time.perf_counter()
    co = np.empty(len(mesh.vertices) * 3, dtype=np.float32)
    mesh.vertices.foreach_get("co", co)
    co = co.reshape(-1, 3)
    normals = np.empty_like(co)
    mesh.vertices.foreach_get("normal", normals.reshape(-1))
    polygons = [tuple(p.vertices) for p in mesh.polygons]
    tree = BVHTree.FromPolygons(co.tolist(), polygons, all_triangles=False, epsilon=0.0)
    build = time.perf_counter() - t
    t = time.perf_counter()
    for i in range(0, len(co), sample):
        direction = -Vector(normals[i].tolist())
        tree.ray_cast(Vector(co[i].tolist()) + direction * 1e-4, direction, 0.5)
    return build + (time.perf_counter() - t) * sample


def main():
    from kodawari.fish import finder, runtime

    bpy.ops.wm.read_homefile(use_empty=True)
    for rings, segments, levels in ((60, 32, 3), (120, 64, 4)):
        obj = smooth_fish.build_smooth_fish(
            "spindle", rings=rings, segments=segments, subdivisions=levels
        )
        for group in list(obj.vertex_groups):
            obj.vertex_groups.remove(group)
        bpy.context.view_layer.objects.active = obj
        obj.select_set(True)
        bpy.ops.kodawari.swim_add(head_axis="POS_X")
        rig = runtime.get_rig(obj)
        n = len(obj.data.vertices)
        t = time.perf_counter()
        search = finder.FinSearch(obj, rig)
        while not search.done:
            search.step()
        native = time.perf_counter() - t
        t = time.perf_counter()
        bpy.ops.kodawari.swim_fin_find()
        whole = time.perf_counter() - t
        baseline = _ray_cast_baseline(obj)
        print(
            f"Find Fins, {n:,} vertices (Blender {bpy.app.version_string}): search {native:.2f} s, "
            f"whole operator {whole:.2f} s ({len(obj.kodawari_swim.fins)} fins); the old finder's "
            f"per-vertex ray cast alone (scaled from 1/20 of the vertices): {baseline:.1f} s = "
            f"{baseline / native:.0f}x our search"
        )
        bpy.data.objects.remove(obj)


main()
