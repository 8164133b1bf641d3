"""A measured prototype, not a feature: the fish bent inside Blender's own evaluation by a
Geometry Nodes modifier reading bound attributes (issue 13's suggested route), beside the
add-on's live shape-key swim, the Geometry Nodes bend of bench_fish.py and Blender's floor.
Not run by `make bench` (its name has no bench_ prefix); run it like the benchmarks:

  source tools/blender_env.sh
  env $(blender_env) KODAWARI_BENCH_SIZES=1000000 /work/main/.venv-bpy5/bin/python -c "import runpy, sys; \
sys.path.insert(0, 'tools'); from blender_install_addon import install_addon; install_addon(); \
runpy.run_path(sys.argv[1], run_name='__main__')" tests/bench/fish_gn_route.py

The route: at bind time the fish mesh gets three attributes per vertex (the FFD coordinates
of docs/algorithms.md §1: table segment, fraction in it, offsets u v w: 20 bytes); per frame
a frame-change handler writes the 1024-segment frame table (origin, e1, e2, e3 and their
change across each segment: 1024 x 8 vectors) into the points of a small helper mesh, and the
modifier computes P' = (O + u e2 + v e3 + w e1) + f (dO + u de2 + v de3 + w de1) with eight
Sample Index nodes and seven vector multiply-adds. No shape key: the user's mesh keeps only
the attributes. The frames come from kodawari_native.ffd_frames with `up` (the live deform
carries the rest normal instead), close enough to measure time and memory.
"""

import gc
import os
import sys

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_fish as bf
import benchlib

print = benchlib.say

SEGMENTS = 1024
FIELDS = ("o", "do", "e1", "de1", "e2", "de2", "e3", "de3")
SIDES = ("kodawari", "gn_route", "geometry_nodes", "floor")


def _enabled(sockets, name=None):
    return next(s for s in sockets if s.enabled and (name is None or s.name == name))


def _named(nodes, name, data_type):
    node = nodes.new("GeometryNodeInputNamedAttribute")
    node.data_type = data_type
    node.inputs["Name"].default_value = name
    return _enabled(node.outputs)


def route_group(table_obj):
    group = bpy.data.node_groups.new("kodawari_ffd_route", "GeometryNodeTree")
    bf._new_socket(group, "Geometry", "INPUT", "NodeSocketGeometry")
    bf._new_socket(group, "Geometry", "OUTPUT", "NodeSocketGeometry")
    nodes, links = group.nodes, group.links
    group_in, group_out = nodes.new("NodeGroupInput"), nodes.new("NodeGroupOutput")
    info = nodes.new("GeometryNodeObjectInfo")
    info.inputs["Object"].default_value = table_obj
    segment = _named(nodes, "kodawari_segment", "INT")
    fraction = _named(nodes, "kodawari_fraction", "FLOAT")
    uvw = nodes.new("ShaderNodeSeparateXYZ")
    links.new(_named(nodes, "kodawari_uvw", "FLOAT_VECTOR"), uvw.inputs[0])
    sampled = {}
    for name in FIELDS:
        sample = nodes.new("GeometryNodeSampleIndex")
        sample.data_type = "FLOAT_VECTOR"
        sample.domain = "POINT"
        links.new(info.outputs["Geometry"], sample.inputs["Geometry"])
        links.new(_named(nodes, name, "FLOAT_VECTOR"), _enabled(sample.inputs, "Value"))
        links.new(segment, sample.inputs["Index"])
        sampled[name] = _enabled(sample.outputs)

    def multiply_add(a, scalar, c):
        node = nodes.new("ShaderNodeVectorMath")
        node.operation = "MULTIPLY_ADD"
        links.new(a, node.inputs[0])
        links.new(scalar, node.inputs[1])  # a float into a vector socket: (s, s, s)
        links.new(c, node.inputs[2])
        return node.outputs[0]

    u, v, w = uvw.outputs["X"], uvw.outputs["Y"], uvw.outputs["Z"]
    at = multiply_add(sampled["e2"], u, sampled["o"])
    at = multiply_add(sampled["e3"], v, at)
    at = multiply_add(sampled["e1"], w, at)
    change = multiply_add(sampled["de2"], u, sampled["do"])
    change = multiply_add(sampled["de3"], v, change)
    change = multiply_add(sampled["de1"], w, change)
    moved = multiply_add(change, fraction, at)
    set_position = nodes.new("GeometryNodeSetPosition")
    links.new(group_in.outputs[0], set_position.inputs["Geometry"])
    links.new(moved, set_position.inputs["Position"])
    links.new(set_position.outputs[0], group_out.inputs[0])
    return group


def table_arrays(axis, up):
    from kodawari import native

    kn = native.module()

    frames = kn.ffd_frames(np.asarray(axis, np.float64), up=up, samples=SEGMENTS + 1)
    o, e1, e2, e3 = (frames[:, k, :] for k in range(4))
    out = {}
    for name, value in (("o", o), ("e1", e1), ("e2", e2), ("e3", e3)):
        out[name] = value[:-1].astype(np.float32)
        out["d" + name] = (value[1:] - value[:-1]).astype(np.float32)
    return out


def make_gn_route(scene, mesh, axes, rest_axis):
    from kodawari import native

    kn = native.module()

    rest = np.empty((len(mesh.vertices), 3), np.float32)
    mesh.vertices.foreach_get("co", rest.reshape(-1))
    up = np.array((0.0, 0.0, 1.0))
    binding = kn.ffd_bind(np.asarray(rest_axis, np.float64), rest, up=up)
    t = binding.t.astype(np.float64) * SEGMENTS
    segment = np.minimum(np.floor(t), SEGMENTS - 1)
    fraction = (t - segment).astype(np.float32)
    uvw = np.stack([binding.u, binding.v, binding.w], axis=1).astype(np.float32)
    del binding, rest, t
    for name, kind, values, key in (
        ("kodawari_segment", "INT", segment.astype(np.int32), "value"),
        ("kodawari_fraction", "FLOAT", fraction, "value"),
        ("kodawari_uvw", "FLOAT_VECTOR", uvw.reshape(-1), "vector"),
    ):
        mesh.attributes.new(name, kind, "POINT").data.foreach_set(key, values)
    del segment, fraction, uvw
    table = bpy.data.meshes.new("ffd_table")
    table.vertices.add(SEGMENTS)
    for name in FIELDS:
        table.attributes.new(name, "FLOAT_VECTOR", "POINT")
    table_obj = bf.add_object(scene, "ffd_table", table)
    obj = bf.add_object(scene, "fish_gn_route", mesh)
    obj.modifiers.new("Fish Swim (GN route)", "NODES").node_group = route_group(table_obj)

    def write_table(frame_scene, *_args):
        if frame_scene != scene:
            return
        arrays = table_arrays(axes[frame_scene.frame_current], up)
        for name in FIELDS:
            table.attributes[name].data.foreach_set("vector", arrays[name].reshape(-1))
        table.update_tag()

    bpy.app.handlers.frame_change_post.append(write_table)
    return obj


def build(side, scene, ring, rings, axes, rest_axis, frames, mesh=None):
    if side == "gn_route":
        if mesh is None:
            mesh = bf.fish_body_mesh("body_gn_route", ring, rings)
        return make_gn_route(scene, mesh, axes, rest_axis)
    return bf.build_side(side, scene, ring, rings, axes, rest_axis, frames, mesh=mesh)


def child(spec):
    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    gc.collect()
    start = benchlib.rss_mb()
    axes = {int(k): v for k, v in spec["axes"].items()}
    frames = list(range(1, spec["frames"] + 2))
    obj = build(spec["side"], scene, spec["ring"], spec["rings"], axes, spec["rest_axis"], frames)
    gc.collect()
    build_peak = benchlib.peak_rss_mb()
    benchlib.reset_peak_rss()
    for frame in frames * benchlib.ROUNDS:
        bf.whole_frame(scene, obj, frame)
    play_peak = benchlib.peak_rss_mb()
    benchlib.child_report(
        {
            "peak_rss_mb": round(max(build_peak, play_peak), 1),
            "above_start_mb": round(play_peak - start, 1),
        }
    )


def main():
    print(
        f"=== fish, the Geometry Nodes route prototype ({benchlib.blender_label()}, load {benchlib.load()})"
    )
    for _count, (ring, rings, per_round) in benchlib.sizes(bf.SIZES).items():
        bpy.ops.wm.read_homefile(use_empty=True)
        main_scene = bpy.context.scene
        main_scene.render.fps = 24
        frames = list(range(2, per_round + 2))
        all_frames = [1, *frames]
        body = bf.fish_body_mesh("body", ring, rings)
        objects, scenes = {"kodawari": None}, {"kodawari": main_scene}
        objects["kodawari"] = bf.build_side("kodawari", main_scene, ring, rings, mesh=body.copy())
        axes, rest_axis = bf.fish_axes(objects["kodawari"], main_scene, all_frames)
        for side in SIDES[1:]:
            scenes[side] = bf.new_scene(side)
            objects[side] = build(
                side, scenes[side], ring, rings, axes, rest_axis, all_frames, mesh=body.copy()
            )
        bpy.data.meshes.remove(body)
        # The route against the live swim, same frame: how far from the exact deform.
        bf.whole_frame(main_scene, objects["kodawari"], 3)
        bf.whole_frame(scenes["gn_route"], objects["gn_route"], 3)
        depsgraph = main_scene.view_layers[0].depsgraph
        ours = objects["kodawari"].evaluated_get(depsgraph).data
        theirs = objects["gn_route"].evaluated_get(scenes["gn_route"].view_layers[0].depsgraph).data
        a = np.empty(len(ours.vertices) * 3, np.float32)
        b = np.empty_like(a)
        ours.vertices.foreach_get("co", a)
        theirs.vertices.foreach_get("co", b)
        error = float(np.abs(a - b).max())
        rows = benchlib.Rounds().run(
            {side: bf.player(scenes[side], objects[side], frames) for side in SIDES}
        )
        del objects, scenes, ours, theirs
        bpy.ops.wm.read_homefile(use_empty=True)
        for side in SIDES:
            rows[side].update(
                benchlib.run_child(
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
            )
        print(
            f"  {ring * rings:>9,} vertices; route vs live swim, largest difference {error:.2e} (body length 1)"
        )
        route = rows["gn_route"]
        for side in SIDES:
            row = rows[side]
            ratio = (
                f"  route / this {route['ms_median'] / row['ms_median']:5.2f}x"
                if side != "gn_route"
                else ""
            )
            mem = ""
            if side != "gn_route" and row.get("above_start_mb") and route.get("above_start_mb"):
                mem = f"  mem {route['above_start_mb'] / row['above_start_mb']:4.2f}x"
            print(
                f"    {side:15s} {benchlib.fmt_ms(row)}  {benchlib.fmt_mem(row)}  load {row['load']:4.1f}{ratio}{mem}"
            )


if __name__ == "__main__":
    spec = benchlib.child_spec()
    if spec is not None:
        child(spec)
    else:
        main()
