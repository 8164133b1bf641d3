"""Fish swim, whole frame against whole frame (run by tools/run_bench.sh in every Blender;
prints figures, never fails on time; writes out/bench.json -> fish).

For a smooth fish-shaped quad body of 100 k, 1 M and 4 M vertices, each side gets the same
per-frame treatment a viewport gives it: `scene.frame_set(f)`, then the depsgraph evaluates
whatever is tagged, then the evaluated mesh's vertex normals are read (a viewport draws them).

  kodawari        the add-on's live swim: the frame handler writes the frame table (1024
                  segments) into the Fish Swim modifier's helper; Blender's evaluation bends
                  the mesh in that Geometry Nodes modifier from the bound (s, u, v) (this body's
                  rest axis is straight: s an attribute, u and v computed from Position;
                  docs/algorithms.md §1.6)
  geometry_nodes  a Geometry Nodes bend of the same mesh along the same animated curve:
                  Sample Curve (factor = position along the body) -> Set Position
                  (curve point + normal * y + binormal * z), built here through the node API
  curve_modifier  Blender's Curve modifier on the same mesh along the same curve
  floor           the same mesh with Basis + one shape key whose value is animated (0.5 and 1,
                  never 0: a key at 0 is skipped): the least Blender does for a mesh that
                  changes every frame

"The same animated curve": a NURBS curve of order 4 with endpoint knots (the clamped cubic
B-spline our FFD uses) whose control points are keyframed, for every frame played, to the
control axis the fish computes at that frame.

Each side lives in its own Scene, so a frame_set evaluates that side only; sides are timed
interleaved round by round in one process (ratios like for like), and each side's peak memory
comes from its own child process (see benchlib).
"""

import gc
import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import benchlib

print = benchlib.say  # each line at once, also through a pipe

# (vertices around, rings along, frames per round: more at 100 k, where a frame is a few ms
# and one busy moment of a shared machine would swing a round)
SIZES = {100_000: (250, 400, 24), 1_000_000: (1000, 1000, 4), 4_000_000: (2000, 2000, 2)}
SIDES = ("kodawari", "geometry_nodes", "curve_modifier", "floor")
LENGTH = 1.0


# ----------------------------------------------------------------------------- the mesh


def fish_body_mesh(name, ring, rings):
    """A closed-profile smooth quad body along +X (head at +X), fish-like taper, ring*rings vertices."""
    s = np.linspace(0.0, 1.0, rings)  # 0 tail .. 1 snout
    x = (s - 0.5) * LENGTH
    half_w = 0.08 * np.sin(np.pi * np.clip(s, 0.02, 0.98)) ** 0.6 + 0.004
    half_h = 1.35 * half_w
    angle = np.linspace(0, 2 * np.pi, ring, endpoint=False)
    co = np.empty((rings, ring, 3), np.float32)
    co[..., 0] = x[:, None]
    co[..., 1] = half_w[:, None] * np.cos(angle)[None, :]
    co[..., 2] = half_h[:, None] * np.sin(angle)[None, :]
    k = np.arange(ring)
    base = (np.arange(rings - 1) * ring)[:, None]
    quads = np.stack(
        [base + k, base + ring + k, base + ring + (k + 1) % ring, base + (k + 1) % ring], -1
    )
    quads = quads.reshape(-1, 4).astype(np.int32)
    mesh = bpy.data.meshes.new(name)
    mesh.vertices.add(ring * rings)
    mesh.vertices.foreach_set("co", co.reshape(-1))
    mesh.loops.add(quads.size)
    mesh.loops.foreach_set("vertex_index", quads.reshape(-1))
    mesh.polygons.add(len(quads))
    mesh.polygons.foreach_set("loop_start", np.arange(0, quads.size, 4, dtype=np.int32))
    if bpy.app.version < (4, 0, 0):
        mesh.polygons.foreach_set("loop_total", np.full(len(quads), 4, np.int32))
    mesh.polygons.foreach_set("use_smooth", np.ones(len(quads), bool))
    mesh.update(calc_edges=True)
    return mesh


# ----------------------------------------------------------------------------- the sides


def new_scene(name):
    scene = bpy.data.scenes.new(name)
    scene.render.fps = 24
    scene.frame_start, scene.frame_end = 1, 250
    return scene


def add_object(scene, name, data):
    obj = bpy.data.objects.new(name, data)
    scene.collection.objects.link(obj)
    return obj


def make_kodawari(scene, mesh):
    """Only in bpy.context.scene: the operator works on the active object."""
    obj = add_object(scene, "fish_kodawari", mesh)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)
    result = bpy.ops.kodawari.swim_add(head_axis="POS_X", preset="CARANGIFORM", frequency=2.0)
    assert result == {"FINISHED"}, result
    obj.select_set(False)
    return obj


def fish_axes(obj, scene, frames):
    """The fish's control axis (K, 3) at each frame, object space; and its rest axis."""
    from kodawari.fish import runtime

    rig = runtime.get_rig(obj)
    axes = {}
    for frame in frames:
        runtime.evaluate(obj, scene, frame)
        axes[frame] = np.array(rig.axis, dtype=np.float64).tolist()
    return axes, np.array(rig.axis_rest, dtype=np.float64).tolist()


def animated_axis_curve(scene, axes):
    """A NURBS curve (order 4, endpoint knots) whose control points follow `axes` frame by frame."""
    frames = sorted(axes)
    count = len(axes[frames[0]])
    data = bpy.data.curves.new("axis", "CURVE")
    data.dimensions = "3D"
    spline = data.splines.new("NURBS")
    spline.points.add(count - 1)
    spline.order_u = 4
    spline.use_endpoint_u = True
    for frame in frames:
        for point, co in zip(spline.points, axes[frame]):
            point.co = (co[0], co[1], co[2], 1.0)
            point.keyframe_insert("co", frame=frame)
    return add_object(scene, "axis", data)


def _new_socket(group, name, in_out, socket_type):
    if hasattr(group, "interface"):  # 4.0+
        group.interface.new_socket(name=name, in_out=in_out, socket_type=socket_type)
    else:  # 3.x
        (group.inputs if in_out == "INPUT" else group.outputs).new(socket_type, name)


def gn_bend_group(curve, rest_axis):
    """Geometry Nodes: position = P(t) + N(t) * (y - y0) + (T x N)(t) * (z - z0), t = (x - x_tail) / length,
    P, T, N from Sample Curve (factor mode) on the axis curve."""
    rest = np.asarray(rest_axis)
    lo, hi = float(rest[:, 0].min()), float(rest[:, 0].max())
    y0, z0 = float(rest[:, 1].mean()), float(rest[:, 2].mean())
    group = bpy.data.node_groups.new("bench_bend", "GeometryNodeTree")
    _new_socket(group, "Geometry", "INPUT", "NodeSocketGeometry")
    _new_socket(group, "Geometry", "OUTPUT", "NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = curve
    info.transform_space = "RELATIVE"
    position = nodes.new("GeometryNodeInputPosition")
    split = nodes.new("ShaderNodeSeparateXYZ")
    links.new(position.outputs[0], split.inputs[0])
    factor = nodes.new("ShaderNodeMath")
    factor.operation = "MULTIPLY_ADD"
    links.new(split.outputs["X"], factor.inputs[0])
    factor.inputs[1].default_value = 1.0 / (hi - lo)
    factor.inputs[2].default_value = -lo / (hi - lo)
    sample = nodes.new("GeometryNodeSampleCurve")
    links.new(info.outputs["Geometry"], sample.inputs[0])
    links.new(factor.outputs[0], sample.inputs["Factor"])
    y = nodes.new("ShaderNodeMath")
    y.operation = "SUBTRACT"
    links.new(split.outputs["Y"], y.inputs[0])
    y.inputs[1].default_value = y0
    z = nodes.new("ShaderNodeMath")
    z.operation = "SUBTRACT"
    links.new(split.outputs["Z"], z.inputs[0])
    z.inputs[1].default_value = z0
    binormal = nodes.new("ShaderNodeVectorMath")
    binormal.operation = "CROSS_PRODUCT"
    links.new(sample.outputs["Tangent"], binormal.inputs[0])
    links.new(sample.outputs["Normal"], binormal.inputs[1])
    along_n = nodes.new("ShaderNodeVectorMath")
    along_n.operation = "SCALE"
    links.new(sample.outputs["Normal"], along_n.inputs[0])
    links.new(y.outputs[0], along_n.inputs["Scale"])
    along_b = nodes.new("ShaderNodeVectorMath")
    along_b.operation = "SCALE"
    links.new(binormal.outputs[0], along_b.inputs[0])
    links.new(z.outputs[0], along_b.inputs["Scale"])
    offset = nodes.new("ShaderNodeVectorMath")
    offset.operation = "ADD"
    links.new(along_n.outputs[0], offset.inputs[0])
    links.new(along_b.outputs[0], offset.inputs[1])
    moved = nodes.new("ShaderNodeVectorMath")
    moved.operation = "ADD"
    links.new(sample.outputs["Position"], moved.inputs[0])
    links.new(offset.outputs[0], moved.inputs[1])
    set_position = nodes.new("GeometryNodeSetPosition")
    links.new(group_in.outputs[0], set_position.inputs["Geometry"])
    links.new(moved.outputs[0], set_position.inputs["Position"])
    links.new(set_position.outputs[0], group_out.inputs[0])
    return group


def make_geometry_nodes(scene, mesh, axes, rest_axis):
    curve = animated_axis_curve(scene, axes)
    obj = add_object(scene, "fish_gn", mesh)
    modifier = obj.modifiers.new("Bend", "NODES")
    modifier.node_group = gn_bend_group(curve, rest_axis)
    return obj


def make_curve_modifier(scene, mesh, axes):
    curve = animated_axis_curve(scene, axes)
    obj = add_object(scene, "fish_curve", mesh)
    modifier = obj.modifiers.new("Curve", "CURVE")
    modifier.object = curve
    modifier.deform_axis = "POS_X"
    return obj


def make_floor(scene, mesh, frames):
    obj = add_object(scene, "fish_floor", mesh)
    obj.shape_key_add(name="Basis")
    pulse = obj.shape_key_add(name="Pulse")
    count = len(mesh.vertices)
    co = np.empty(count * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    (getattr(pulse, "points", None) or pulse.data).foreach_set("co", co * 1.02)
    # Never 0: Blender skips a key whose value is 0 when it mixes the keys, so a value keyed
    # 0, 1, 0, 1 made every other floor frame a copy of the Basis alone (the live swim's key
    # is always at 1 and mixed every frame). 0.5 and 1 alternate: every frame mixes the key.
    for frame in frames:
        pulse.value = 0.5 + 0.5 * (frame % 2)
        pulse.keyframe_insert("value", frame=frame)
    return obj


def build_side(side, scene, ring, rings, axes=None, rest_axis=None, frames=(), mesh=None):
    """One side's objects in `scene`, on a new body mesh (or on `mesh`, a plain copy of it)."""
    if mesh is None:
        mesh = fish_body_mesh(f"body_{side}", ring, rings)
    if side == "kodawari":
        return make_kodawari(scene, mesh)
    if side == "geometry_nodes":
        return make_geometry_nodes(scene, mesh, axes, rest_axis)
    if side == "curve_modifier":
        return make_curve_modifier(scene, mesh, axes)
    return make_floor(scene, mesh, frames)


# ----------------------------------------------------------------------------- one frame


def detach_frame_handler():
    """Takes the swim's frame handler out of frame_change_post, for benchmarks that write the
    frames themselves (so no copy is bound again by it); put it back with post.append."""
    post = bpy.app.handlers.frame_change_post
    handler = next(h for h in post if getattr(h, "__name__", "") == "on_frame_change")
    post.remove(handler)
    return handler


def frame_tables(fish, scene, frames):
    """Each frame's table (the core's, as the live handler computes it), computed once."""
    from kodawari.fish import runtime, timing

    rig = runtime.get_rig(fish)
    settings = fish.kodawari_swim
    tables = {}
    for frame in frames:
        phase, _ = timing.phase_and_distance(fish, settings, scene, frame, rig.body_length)
        tables[frame] = rig.frame(settings, phase)[0].copy()
    return rig, tables


def copy_in_own_scene(fish, name, node_group):
    """A copy of the fish (same mesh) in a scene of its own whose Fish Swim runs `node_group`:
    a frame there evaluates that tree alone, and no group is swapped while timing."""
    from kodawari.fish import route

    scene = new_scene(name)
    obj = fish.copy()
    scene.collection.objects.link(obj)
    route.modifier(obj).node_group = node_group
    scene.frame_set(1)  # makes the scene's depsgraph
    return scene, obj


def whole_frame(scene, obj, frame):
    """What a viewport does per frame: frame_set, evaluate what handlers tagged, read normals.
    Returns the tail vertex of the evaluated mesh (to check that it moves)."""
    scene.frame_set(frame)
    depsgraph = scene.view_layers[0].depsgraph
    depsgraph.update()
    mesh = obj.evaluated_get(depsgraph).data
    normal = mesh.vertices[0].normal
    return tuple(mesh.vertices[len(mesh.vertices) - 1].co) + tuple(normal)


def player(scene, obj, frames):
    def play(_round):
        whole_frame(scene, obj, 1)  # untimed: every round plays the same frames from the same start
        seconds = []
        for frame in frames:
            start = time.perf_counter()
            whole_frame(scene, obj, frame)
            seconds.append(time.perf_counter() - start)
        return seconds

    return play


def moves(scene, obj, frames):
    return len({whole_frame(scene, obj, f) for f in frames[:2]}) > 1


# ----------------------------------------------------------------------------- child: one side's memory


def child(spec):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    gc.collect()
    start = benchlib.rss_mb()
    axes = {int(k): v for k, v in spec["axes"].items()}
    frames = list(range(1, spec["frames"] + 2))
    obj = build_side(
        spec["side"], scene, spec["ring"], spec["rings"], axes, spec["rest_axis"], frames
    )
    gc.collect()
    build_peak = benchlib.peak_rss_mb()
    benchlib.reset_peak_rss()  # from here: the peak while playing
    # The frames played ROUNDS times over, as the timing does: a side's memory may still grow
    # after its first few frames (the Geometry Nodes bend's did, up to the fourth in 5.0).
    for frame in frames * benchlib.ROUNDS:
        whole_frame(scene, obj, frame)
    play_peak = benchlib.peak_rss_mb()
    benchlib.child_report(
        {
            "peak_rss_mb": round(max(build_peak, play_peak), 1),
            "above_start_mb": round(play_peak - start, 1),
            "play_peak_mb": round(play_peak, 1),
            "build_peak_mb": round(build_peak, 1),
            "start_mb": round(start, 1),
        }
    )


# ----------------------------------------------------------------------------- parent


def core_deform(rig, packed, out):
    """The whole mesh deformed in the core: frame table, then every vertex (bake, Apply)."""
    rig.binding.frame_table(rig.axis, rig.table)
    rig.kn.ffd_deform_packed(rig.table, packed, rig.end_scale, out)


def solver_alone(obj, scene, frames):
    """The add-on's own per-frame work without Blender's evaluation: runtime.evaluate
    (phase, body axis, frame table, helper write), and the core's whole-mesh deform alone
    (what a bake or Apply computes per frame, not the live path)."""
    from kodawari.fish import runtime

    rig = runtime.get_rig(obj)
    out = np.empty((rig.count, 3), np.float32)
    packed = rig.packed_coordinates()  # the bound coordinates, read (or computed) once
    evaluate, deform = [], []
    for _ in range(benchlib.ROUNDS):
        evaluate.append(
            np.mean([benchlib.timed(lambda f=f: runtime.evaluate(obj, scene, f)) for f in frames])
        )
        deform.append(
            np.mean([benchlib.timed(lambda: core_deform(rig, packed, out)) for _ in frames])
        )
    return {
        "handler_ms_min": round(min(evaluate) * 1e3, 3),
        "handler_ms_median": round(float(np.median(evaluate)) * 1e3, 3),
        "deform_ms_min": round(min(deform) * 1e3, 3),
        "deform_ms_median": round(float(np.median(deform)) * 1e3, 3),
    }


def measure_size(count, ring, rings, per_round):
    bpy.ops.wm.read_homefile(use_empty=True)
    main_scene = bpy.context.scene
    main_scene.render.fps = 24
    frames = list(range(2, per_round + 2))
    all_frames = [1, *frames]
    t = time.perf_counter()
    objects, scenes = {}, {}
    scenes["kodawari"] = main_scene
    body = fish_body_mesh(
        "body", ring, rings
    )  # the other sides bend copies of it (faster than rebuilding)
    objects["kodawari"] = build_side("kodawari", main_scene, ring, rings, mesh=body.copy())
    axes, rest_axis = fish_axes(objects["kodawari"], main_scene, all_frames)
    for side in SIDES[1:]:
        scenes[side] = new_scene(side)
        objects[side] = build_side(
            side, scenes[side], ring, rings, axes, rest_axis, all_frames, mesh=body.copy()
        )
    bpy.data.meshes.remove(body)
    setup = time.perf_counter() - t
    moved = {side: moves(scenes[side], objects[side], frames) for side in SIDES}
    plays = {side: player(scenes[side], objects[side], frames) for side in SIDES}
    rows = benchlib.Rounds().run(plays)
    solver = solver_alone(objects["kodawari"], main_scene, frames)
    process_peak = benchlib.peak_rss_mb()
    del objects, scenes
    bpy.ops.wm.read_homefile(use_empty=True)  # free this size before its children run
    for side in SIDES:
        memory = benchlib.run_child(
            __file__,
            {
                "side": side,
                "ring": ring,
                "rings": rings,
                "frames": per_round,
                "axes": axes,
                "rest_axis": rest_axis,
            },
        )
        rows[side].update(memory)
        rows[side]["moves"] = moved[side]
        rows[side]["vertices"] = ring * rings
        rows[side]["frames_per_round"] = per_round
    return {
        "vertices": ring * rings,
        "rows": rows,
        "solver": solver,
        "setup_s": round(setup, 1),
        "timing_process_peak_mb": round(process_peak, 1),
    }


def main():
    print(
        f"=== fish, whole frame ({benchlib.blender_label()}, {os.cpu_count()} CPUs, load {benchlib.load()}): "
        f"ms per frame min / median of {benchlib.ROUNDS} rounds; peak RSS per side in its own process"
    )
    results = []
    for count, (ring, rings, per_round) in benchlib.sizes(SIZES).items():
        size = measure_size(count, ring, rings, per_round)
        results.append(size)
        rows = size["rows"]
        ours = rows["kodawari"]
        print(
            f"  {size['vertices']:>9,} vertices ({per_round} frames/round, set-up {size['setup_s']} s):"
        )
        for side in SIDES:
            row = rows[side]
            ratio = (
                ""
                if side == "kodawari"
                else f"  kodawari / this {ours['ms_median'] / row['ms_median']:5.2f}x"
            )
            mem_ratio = ""
            if side != "kodawari" and row.get("above_start_mb") and ours.get("above_start_mb"):
                mem_ratio = f"  mem {ours['above_start_mb'] / row['above_start_mb']:4.2f}x"
            err = f"  [memory child: {row['error']}]" if "error" in row else ""
            print(
                f"    {side:15s} {benchlib.fmt_ms(row)}  {benchlib.fmt_mem(row)}  load {row['load']:4.1f}"
                f"{ratio}{mem_ratio}{'' if row['moves'] else '  (DID NOT MOVE)'}{err}"
            )
        s = size["solver"]
        print(
            f"    solver alone: handler (phase + FFD + write) {s['handler_ms_min']:.2f} / {s['handler_ms_median']:.2f} ms,"
            f" native deform {s['deform_ms_min']:.2f} / {s['deform_ms_median']:.2f} ms"
            f" = {s['deform_ms_min'] * 1e6 / size['vertices']:.2f} ns/vertex"
        )
        benchlib.record("fish", results)


if __name__ == "__main__":
    spec = benchlib.child_spec()
    if spec is not None:
        child(spec)
    else:
        main()
