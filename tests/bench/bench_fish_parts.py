"""Where a live fish frame goes at 100 k vertices (run by tools/run_bench.sh in every Blender;
prints figures, never fails on time; writes out/bench.json -> fish_parts).

The smooth body of bench_fish.py, swimming live. Each part is timed as CPU time per frame (all
threads of this process: on a machine shared with other jobs it moves less with the load than
wall time), the parts interleaved round by round as in every benchmark here:

  handler         runtime.evaluate alone: body axis, frame table, the helper's write
  helper          writing and tagging the helper, its evaluation and an empty pass of the
                  modifier (a tree that passes the mesh through, still depending on the helper)
  set_position    the Fish Swim tree cut down to Set Position from one bound attribute
  first_sample    ... plus Floor and one Sample Index on the helper
  fish_swim       the whole Fish Swim tree, as it plays (docs/algorithms.md §1.6): this body's
                  rest axis is straight, so u and v are computed from Position, s is read
  stored_suv      the same tree reading all three of (s, u, v) from attributes (what a fish whose
                  rest axis curves gets, and every fish before), on a copy carrying them
  + normals       the same frame with the evaluated vertex normals read (as a viewport does)
  geometry_nodes  the Geometry Nodes bend's frame of bench_fish.py (its curve's animation and
                  its tree), no normals read
  floor           the floor's frame of bench_fish.py (the shape-key value mixed in), no normals
"""

import os
import sys
import time

import bpy
import numpy as np

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import bench_fish
import benchlib

print = benchlib.say  # each line at once, also through a pipe

SIZES = {100_000: (250, 400)}
FRAMES = 10
TREE_PARTS = ("helper", "set_position", "first_sample", "fish_swim")


def cut_down_group(table_obj, part):
    """The Fish Swim tree reduced to its first nodes (route.build_group's, in its order)."""
    from kodawari.fish import route

    group = bpy.data.node_groups.new(f"bench {part}", "GeometryNodeTree")
    for in_out in ("INPUT", "OUTPUT"):
        route._new_socket(group, "Geometry", in_out)
    tree = route._Tree(group)
    geometry = tree.node("NodeGroupInput").outputs[0]
    table = tree.object_geometry("frames", table_obj)  # the helper, a dependency in every part
    if part != "helper":
        s = tree.named(route.COORDINATES[0], "FLOAT")
        if part == "set_position":
            position = s  # one bound attribute, as a vector (s, s, s)
        else:
            position = tree.sample(table, "o", tree.math("FLOOR", s, 0.0))
        set_position = tree.node("GeometryNodeSetPosition")
        tree.links.new(geometry, set_position.inputs["Geometry"])
        tree.links.new(position, set_position.inputs["Position"])
        geometry = set_position.outputs[0]
        for name in route.COORDINATES:
            remove = tree.node("GeometryNodeRemoveAttribute")
            remove.inputs["Name"].default_value = name
            tree.links.new(geometry, remove.inputs["Geometry"])
            geometry = remove.outputs[0]
    tree.links.new(geometry, tree.node("NodeGroupOutput").inputs[0])
    return group


def cpu_per_frame(frame_once):
    def play(_round):
        frame_once(1)  # untimed: every round starts from the same frame
        seconds = []
        for frame in range(2, FRAMES + 2):
            start = time.process_time()
            frame_once(frame)
            seconds.append(time.process_time() - start)
        return seconds

    return play


def measure(ring, rings):
    from kodawari.fish import route, runtime

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    frames = list(range(1, FRAMES + 2))
    body = bench_fish.fish_body_mesh("body", ring, rings)
    fish = bench_fish.build_side("kodawari", scene, ring, rings, mesh=body.copy())
    axes, rest_axis = bench_fish.fish_axes(fish, scene, frames)
    others = {}
    for side in ("geometry_nodes", "floor"):
        other_scene = bench_fish.new_scene(side)
        obj = bench_fish.build_side(
            side, other_scene, ring, rings, axes, rest_axis, frames, mesh=body.copy()
        )
        others[side] = (other_scene, obj)
    bpy.data.meshes.remove(body)
    # The evaluation parts are driven here, not by the frame handler.
    handler = bench_fish.detach_frame_handler()
    rig, tables = bench_fish.frame_tables(fish, scene, frames)
    swim_group = route.modifier(fish).node_group
    table_obj = swim_group.nodes["frames"].inputs[0].default_value
    # Each cut-down tree on its own copy of the fish.
    parts = {"fish_swim": (scene, fish)}
    for part in TREE_PARTS[:-1]:
        parts[part] = bench_fish.copy_in_own_scene(fish, part, cut_down_group(table_obj, part))

    # The whole tree as it was before u and v could be computed: all three read.
    stored_obj = fish.copy()
    stored_obj.data = fish.data.copy()
    packed = rig.packed_coordinates()
    # The helper carries the constants and signs of the fish's computed u and v (route._rows):
    # stored without them, the copy shows the same shape from the same helper.
    packed[:, 1:] -= np.asarray(swim_group.get("kodawari_offsets", (0.0, 0.0)), np.float32)
    packed[:, 1:] *= np.asarray(swim_group.get("kodawari_signs", (1.0, 1.0)), np.float32)
    for k, name in enumerate(route.COORDINATES):
        if stored_obj.data.attributes.find(name) < 0:
            attribute = stored_obj.data.attributes.new(name, "FLOAT", "POINT")
            attribute.data.foreach_set("value", packed[:, k].copy())
    route.modifier(stored_obj).node_group = route.build_group(
        table_obj, None, rig.end_scale, with_ends=route.has_ends(packed)
    )
    del packed
    stored_scene = bench_fish.new_scene("stored_suv")
    stored_scene.collection.objects.link(stored_obj)
    stored_scene.frame_set(1)
    parts["stored_suv"] = (stored_scene, stored_obj)

    def tree_frame(part, normals=False):
        part_scene, obj = parts[part]
        depsgraph = part_scene.view_layers[0].depsgraph

        def once(frame):
            route.write_frame(fish, tables[frame], None)
            depsgraph.update()
            mesh = obj.evaluated_get(depsgraph).data
            if normals:
                tuple(mesh.vertices[0].normal)

        return once

    def other_frame(side):
        other_scene, obj = others[side]

        def once(frame):
            other_scene.frame_set(frame)
            other_scene.view_layers[0].depsgraph.update()

        return once

    plays = {"handler": cpu_per_frame(lambda f: runtime.evaluate(fish, scene, f))}
    plays.update({part: cpu_per_frame(tree_frame(part)) for part in (*TREE_PARTS, "stored_suv")})
    plays["+ normals"] = cpu_per_frame(tree_frame("fish_swim", normals=True))
    plays.update({side: cpu_per_frame(other_frame(side)) for side in others})
    rows = benchlib.Rounds(rounds=5).run(plays)
    bpy.app.handlers.frame_change_post.append(handler)
    return rows


def main():
    print(
        f"=== fish, parts of a live frame ({benchlib.blender_label()}, {os.cpu_count()} CPUs, "
        f"load {benchlib.load()}): CPU ms per frame, min / median of 5 rounds of {FRAMES} frames"
    )
    results = []
    for count, (ring, rings) in benchlib.sizes(SIZES).items():
        rows = measure(ring, rings)
        print(f"  {ring * rings:>9,} vertices:")
        for part, row in rows.items():
            print(f"    {part:15s} {benchlib.fmt_ms(row)}  load {row['load']:4.1f}")
        whole = rows["+ normals"]["ms_median"]
        normals = whole - rows["fish_swim"]["ms_median"]
        print(
            f"    normals read: {normals:.2f} ms of the swim's {whole:.2f} ms frame;"
            f" the tree beyond the floor's shape-key mix:"
            f" {rows['fish_swim']['ms_median'] - rows['floor']['ms_median']:.2f} ms"
        )
        print(
            f"    u, v from Position instead of attributes: the tree"
            f" {rows['fish_swim']['ms_median'] / rows['stored_suv']['ms_median']:.2f}x"
        )
        results.append({"vertices": count, "rows": rows})
    benchlib.record("fish_parts", results)


if __name__ == "__main__":
    main()
