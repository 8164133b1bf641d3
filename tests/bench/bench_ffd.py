"""Bending a ~1M-vertex mesh along an animated curve: Blender's Curve modifier
against kodawari's control-axis FFD, in one Blender process (issue 2).

Run with the add-on installed:  bash tools/run_bench.sh   (after `make addon`;
it runs this in Blender 3.4, then under the bpy 4.5 and 5.0 modules).
Prints figures and ratios only; never passes or fails on time.

For two meshes of the same ~1M vertices -- a quad tube (a real surface: Blender
3.4 recomputes its normals on every evaluation) and the same vertices without
faces -- per frame, best and median of FRAMES frames:
(a) Curve modifier: a mesh object with a Curve modifier on a NURBS curve (order
    4, endpoints: the same clamped cubic B-spline kodawari uses) whose control
    points are keyframed; scene.frame_set() evaluates animation and modifier.
(b) kodawari: ffd_bind once; per frame scene.frame_set(), deform into a
    preallocated array, write it back with foreach_set, tag, depsgraph update:
    (b1) into a shape key (ShapeKey.data has no raw-array fast path in 3.4;
         ShapeKey.points, 4.1+, has),
    (b2) into the mesh's vertex positions (MeshVertex.co in 3.4, the
         "position" attribute from 3.5).
(c) Blender's floor for a write-back: write the unchanged rest positions and
    re-evaluate -- what writing into this mesh from Python costs before any
    deforming. In 3.4 it re-copies the whole mesh and recomputes normals; the
    Curve modifier path (a) does not re-copy, so (a) - (c) understates it there.
Every variant then reads the evaluated mesh (vertex count and the tail vertex),
so the timed work includes Blender's evaluation.
"""

import os
import statistics
import sys
import time

import bpy
import numpy as np

RING = 1000        # vertices around the tube
RINGS = 1000       # rings along it: RING * RINGS ~ 1M vertices
LENGTH = 4.0
CONTROL_POINTS = 8
FRAMES = 6
NATIVE_SIZES = (10_000, 100_000, 1_000_000, 4_000_000)


def native_module():
    try:
        from kodawari import native  # the installed add-on
        return native.module()
    except ImportError:
        sys.path.insert(0, os.path.join(os.path.dirname(__file__), "..", "..", "addon", "kodawari"))
        import kodawari_native
        return kodawari_native


def tube_mesh(name):
    """A closed quad tube along +x from 0 to LENGTH: RING x RINGS vertices."""
    angle = np.linspace(0, 2 * np.pi, RING, endpoint=False)
    x = np.linspace(0, LENGTH, RINGS)
    radius = 0.1 + 0.25 * np.sin(np.pi * x / LENGTH) ** 0.7
    co = np.empty((RINGS, RING, 3), np.float32)
    co[..., 0] = x[:, None]
    co[..., 1] = radius[:, None] * np.cos(angle)[None, :]
    co[..., 2] = 0.6 * radius[:, None] * np.sin(angle)[None, :]
    ring = np.arange(RING)
    base = (np.arange(RINGS - 1) * RING)[:, None]
    quads = np.stack([base + ring, base + (ring + 1) % RING, base + RING + (ring + 1) % RING, base + RING + ring],
                     axis=-1).reshape(-1, 4)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(RING * RINGS)
    mesh.vertices.foreach_set("co", co.reshape(-1))
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads.reshape(-1).astype(np.int32))
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", (np.arange(len(quads)) * 4).astype(np.int32))
    mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, np.int32))
    mesh.update(calc_edges=True)
    mesh.validate()
    return mesh, co.reshape(-1, 3).copy()


def axis_at(frame):
    """The animated control polygon: a travelling wave growing toward the tail."""
    s = np.linspace(0, 1, CONTROL_POINTS)
    points = np.zeros((CONTROL_POINTS, 3))
    points[:, 0] = LENGTH * s
    points[:, 1] = 0.6 * s * s * np.sin(2 * np.pi * s - 0.7 * frame)
    return points


def animated_nurbs_curve():
    """A NURBS curve of order 4 with endpoints: the same clamped cubic B-spline as ours."""
    curve = bpy.data.curves.new("axis", "CURVE")
    curve.dimensions = "3D"
    spline = curve.splines.new("NURBS")
    spline.points.add(CONTROL_POINTS - 1)
    spline.order_u = 4
    spline.use_endpoint_u = True
    for frame in range(1, FRAMES + 2):
        for point, co in zip(spline.points, axis_at(frame)):
            point.co = (*co, 1.0)
            point.keyframe_insert("co", frame=frame)
    obj = bpy.data.objects.new("axis", curve)
    bpy.context.scene.collection.objects.link(obj)
    return obj


def evaluated_probe(obj):
    """Reads the evaluated mesh: its vertex count and the tail vertex."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).data
    return len(mesh.vertices), tuple(mesh.vertices[len(mesh.vertices) - 1].co)


def without_faces(mesh, rest):
    points = bpy.data.meshes.new(mesh.name + "_points")
    points.vertices.add(len(rest))
    points.vertices.foreach_set("co", rest.reshape(-1))
    points.update()
    return points


def vertex_positions_target(mesh):
    """The fastest bulk handle on a mesh's vertex positions: the "position"
    attribute (3.5+; MeshVertex.co lost its raw-array path in 4.x), else vertices."""
    position = mesh.attributes.get("position")
    if position is not None and position.data_type == "FLOAT_VECTOR" and position.domain == "POINT":
        return position.data, "vector"
    return mesh.vertices, "co"


def timed_frames(scene, obj, per_frame):
    """Seconds per frame of per_frame(frame) + reading the evaluated mesh, as
    (best, median) over FRAMES frames -- the best is the least disturbed by the
    other jobs sharing this machine -- and whether the evaluated tail vertex
    moved from frame to frame."""
    per_frame(FRAMES + 1)  # warm up: the first evaluation builds caches
    evaluated_probe(obj)
    times, tails = [], set()
    for frame in range(1, FRAMES + 1):
        start = time.perf_counter()
        per_frame(frame)
        count, tail = evaluated_probe(obj)
        times.append(time.perf_counter() - start)
        tails.add(tail)
    return (min(times), statistics.median(times)), len(tails) > 1


def with_object(scene, mesh, run):
    obj = bpy.data.objects.new(mesh.name, mesh)
    scene.collection.objects.link(obj)
    try:
        return run(obj)
    finally:
        bpy.data.objects.remove(obj)
        bpy.data.meshes.remove(mesh)


def curve_modifier_variant(scene, mesh, axis):
    def run(obj):
        modifier = obj.modifiers.new("Curve", "CURVE")
        modifier.object = axis
        modifier.deform_axis = "POS_X"
        return timed_frames(scene, obj, scene.frame_set)
    return with_object(scene, mesh.copy(), run)


def kodawari_variant(scene, mesh, binding, into_shape_key):
    out = np.empty((len(mesh.vertices), 3), np.float32)
    flat = out.reshape(-1)

    def run(obj):
        target, field = vertex_positions_target(obj.data)
        if into_shape_key:
            obj.shape_key_add(name="Basis")
            key = obj.shape_key_add(name="kodawari_ffd")
            key.value = 1.0
            # ShapeKey.points (4.1+) has the raw-array fast path; 3.4 only has .data.
            target, field = getattr(key, "points", None) or key.data, "co"

        def per_frame(frame):
            scene.frame_set(frame)
            binding.deform(axis_at(frame), out)
            target.foreach_set(field, flat)
            obj.data.update_tag()
            bpy.context.evaluated_depsgraph_get().update()
        return timed_frames(scene, obj, per_frame)
    return with_object(scene, mesh.copy(), run)


def floor_variant(scene, mesh, rest):
    flat = rest.reshape(-1)

    def run(obj):
        target, field = vertex_positions_target(obj.data)

        def per_frame(frame):
            scene.frame_set(frame)
            target.foreach_set(field, flat)
            obj.data.update_tag()
            bpy.context.evaluated_depsgraph_get().update()
        seconds, _ = timed_frames(scene, obj, per_frame)
        return seconds, None
    return with_object(scene, mesh.copy(), run)


def round_trip(scene, kn):
    tube, rest = tube_mesh("tube")
    points = without_faces(tube, rest)
    axis = animated_nurbs_curve()
    count = len(rest)
    start = time.perf_counter()
    binding = kn.ffd_bind(axis_at(0), rest)
    bind_seconds = time.perf_counter() - start
    out = np.empty_like(rest)
    deform = []
    for frame in range(1, FRAMES + 1):
        start = time.perf_counter()
        binding.deform(axis_at(frame), out)
        deform.append(time.perf_counter() - start)
    ns = lambda seconds: seconds * 1e9 / count  # noqa: E731
    print(f"\nbend {count} vertices along an animated {CONTROL_POINTS}-point curve; per frame, best (median) of "
          f"{FRAMES} frames; ffd_bind once: {bind_seconds:.2f} s; native deform alone: {ns(min(deform)):.1f} ns/vertex")
    for label, mesh in (("quad tube (faces)", tube), ("same vertices, no faces", points)):
        rows = (
            ("(a)  Curve modifier: frame_set + evaluation", curve_modifier_variant(scene, mesh, axis)),
            ("(b1) kodawari -> shape key + update", kodawari_variant(scene, mesh, binding, into_shape_key=True)),
            ("(b2) kodawari -> vertex positions + update", kodawari_variant(scene, mesh, binding, into_shape_key=False)),
            ("(c)  Blender floor: rewrite rest positions + update", floor_variant(scene, mesh, rest)),
        )
        print(f"\n  {label}")
        best_a = rows[0][1][0][0]
        for name, ((best, median), moved) in rows:
            ratio = f"  ratio a/this {best_a / best:5.1f}x" if name[1] == "b" else ""
            moves = "" if moved is None else f"  (tail moves: {moved})"
            print(f"    {name:54s} {ns(best):7.1f} ({ns(median):6.1f}) ns/vertex{ratio}{moves}")
        a, b2, c = rows[0][1][0][0], rows[2][1][0][0], rows[3][1][0][0]
        print(f"    cost above the write-back floor (c): Curve modifier {ns(a - c):6.1f}, kodawari (b2) "
              f"{ns(max(b2 - c, 0)):6.1f} ns/vertex")
    for mesh in (tube, points):
        bpy.data.meshes.remove(mesh)


def native_scaling(kn):
    rng = np.random.default_rng(0)
    rows = []
    for size in NATIVE_SIZES:
        x = rng.uniform(-0.1, LENGTH + 0.1, size)
        angle = rng.uniform(0, 2 * np.pi, size)
        radius = 0.3 * rng.random(size)
        vertices = np.column_stack([x, radius * np.cos(angle), radius * np.sin(angle)]).astype(np.float32)
        vertices = vertices[np.argsort(x, kind="stable")]  # mesh order follows the body, as real meshes do
        vertices = np.ascontiguousarray(vertices)
        start = time.perf_counter()
        binding = kn.ffd_bind(axis_at(0), vertices)
        bind_seconds = time.perf_counter() - start
        out = np.empty_like(vertices)
        axis = axis_at(3)
        binding.deform(axis, out)
        repeats = max(3, int(1e7 // size))
        best = float("inf")
        for _ in range(3):
            start = time.perf_counter()
            for _ in range(repeats):
                binding.deform(axis, out)
            best = min(best, (time.perf_counter() - start) / repeats)
        single = float("inf")
        for _ in range(3):
            start = time.perf_counter()
            binding.deform(axis, out, threads=1)
            single = min(single, time.perf_counter() - start)
        rows.append((size, best * 1e9 / size, single * 1e9 / size, bind_seconds * 1e9 / size))
        del binding, vertices, out
    return rows


def main():
    kn = native_module()
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.frame_start, scene.frame_end = 1, FRAMES + 1
    print(f"Blender {bpy.app.version_string}, kodawari_native {kn.__version__}, "
          f"{os.cpu_count()} logical CPUs (shared machine: figures vary run to run)")
    round_trip(scene, kn)
    print("\nnative deform alone (all cores / 1 thread), and ffd_bind, per vertex:")
    print("  vertices    ns/vertex   ns/vertex 1 thread   bind ns/vertex")
    for size, ns, ns_single, ns_bind in native_scaling(kn):
        print(f"  {size:>9}  {ns:9.2f}   {ns_single:9.2f}            {ns_bind:9.1f}")


main()
