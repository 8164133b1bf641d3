"""What the Fish Swim tree's nodes cost per vertex, and the 4x4-matrix tree tried against it
(run by tools/run_bench.sh in every Blender; prints figures, never fails on time; writes
out/bench.json -> fish_nodes). docs/algorithms.md §1.6 quotes it.

The smooth body of bench_fish.py at 1 M vertices (KODAWARI_BENCH_SIZES=100000 for a quick
look), swimming live. Each tree below bends its own copy of the fish in its own scene; a frame
is: the frame's table written into the helper, the depsgraph evaluated (no normals read), wall
time, the trees interleaved round by round:

  pass            Set Position from Position (the modifier, the helper's evaluation and Set
                  Position's write: what every tree below pays)
  multiply_add x4 four vector Multiply Add whose scale is a float (converted to a vector per
                  link, as the Fish Swim tree's u, v and fraction are)
  vector_madd x4  the same with a vector scale (no conversion)
  add x4          four vector Add
  sample x1       Floor of s and one Sample Index (float3) on the helper
  sample x6       the same with six Sample Index nodes, summed by five Add (the tree's six rows)
  transform x4    four Transform Point with one matrix (Blender 4.2+)
  fish_swim       the Fish Swim tree as route.build_group makes it for this body
  matrix          the same bend from two 4x4 rows per segment (Blender 4.2+): A = [e2 n_u^T + e3
                  n_v^T | O + c_u e2 + c_v e3] and its change, sampled as FLOAT4X4 and applied
                  by two Transform Point: P' = A P + f (dA P), with u and v folded into the rows

Per node, ns per vertex = (the chain - pass) / nodes / vertices.
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

SIZES = {1_000_000: (1000, 1000), 100_000: (250, 400)}
FRAMES = 8
MATRICES = bpy.app.version >= (4, 2, 0)  # FLOAT4X4 attributes and matrix sockets


def _vector_node(tree, operation, a, b, c=None):
    node = tree.node("ShaderNodeVectorMath", operation=operation)
    for socket, value in zip(node.inputs, (a, b, c)):
        if value is not None:
            tree.links.new(value, socket)
    return node.outputs[0]


def chain(kind):
    """A tree body: (tree, table geometry, s, position) -> the new position socket."""

    def body(tree, table, s, position):
        if kind.startswith("sample"):
            segment = tree.math("FLOOR", s, 0.0)
            out = None
            for name in ("o", "do", "e2", "de2", "e3", "de3")[: 6 if kind == "sample6" else 1]:
                row = tree.sample(table, name, segment)
                out = row if out is None else _vector_node(tree, "ADD", out, row)
            return out
        out = position
        matrix = None
        if kind == "transform":
            matrix = tree.node("FunctionNodeCombineTransform").outputs[0]
        for _ in range(0 if kind == "pass" else 4):
            if kind == "multiply_add":
                out = tree.multiply_add(out, s, position)
            elif kind == "vector_madd":
                out = _vector_node(tree, "MULTIPLY_ADD", out, position, position)
            elif kind == "add":
                out = _vector_node(tree, "ADD", out, position)
            else:
                node = tree.node("FunctionNodeTransformPoint")
                tree.links.new(out, node.inputs[0])
                tree.links.new(matrix, node.inputs[1])
                out = node.outputs[0]
        return out

    return body


def matrix_rows(table, rows, out):
    """The frame table (8 * 1024, 3) as (2, 1025, 16) column-major 4x4: A and its change dA
    (module docstring); row 1024 is the tail's frame with no change, as route._rows."""
    from kodawari.fish import route

    full = route._rows(table, np.empty((len(route.FIELDS), route.ROWS, 3), np.float32))
    full = full.astype(np.float64)
    o, do, _e1, _de1, e2, de2, e3, de3 = full
    (n_u, c_u), (n_v, c_v) = ((np.asarray(r[:3], np.float64), float(r[3])) for r in rows[1:])
    for k, (origin, a, b) in enumerate(((o, e2, e3), (do, de2, de3))):
        m = np.zeros((route.ROWS, 4, 4))  # [row][column][line]: column-major
        m[:, :3, :3] = n_u[None, :, None] * a[:, None, :] + n_v[None, :, None] * b[:, None, :]
        m[:, 3, :3] = origin + c_u * a + c_v * b
        m[:, 3, 3] = 1.0 if k == 0 else 0.0
        out[k] = m.reshape(route.ROWS, 16)
    return out


def matrix_group(tree, table, s, position):
    segment = tree.math("FLOOR", s, 0.0)
    fraction = tree.math("SUBTRACT", s, segment)
    points = []
    for name in ("A", "dA"):
        sample = tree.node("GeometryNodeSampleIndex", data_type="FLOAT4X4", domain="POINT")
        tree.links.new(table, sample.inputs["Geometry"])
        value = next(x for x in sample.inputs if x.enabled and x.name == "Value")
        tree.links.new(tree.named(name, "FLOAT4X4"), value)
        tree.links.new(segment, sample.inputs["Index"])
        point = tree.node("FunctionNodeTransformPoint")
        tree.links.new(position, point.inputs[0])
        tree.links.new(next(x for x in sample.outputs if x.enabled), point.inputs[1])
        points.append(point.outputs[0])
    return tree.multiply_add(points[1], fraction, points[0])


def new_group(name, table_obj, body):
    from kodawari.fish import route

    group = bpy.data.node_groups.new(name, "GeometryNodeTree")
    for in_out in ("INPUT", "OUTPUT"):
        route._new_socket(group, "Geometry", in_out)
    tree = route._Tree(group)
    geometry = tree.node("NodeGroupInput").outputs[0]
    table = tree.object_geometry("frames", table_obj)
    s = tree.named(route.COORDINATES[0], "FLOAT")
    position = tree.node("GeometryNodeInputPosition").outputs[0]
    set_position = tree.node("GeometryNodeSetPosition")
    tree.links.new(geometry, set_position.inputs["Geometry"])
    tree.links.new(body(tree, table, s, position), set_position.inputs["Position"])
    remove = tree.node("GeometryNodeRemoveAttribute")
    remove.inputs["Name"].default_value = route.COORDINATES[0]
    tree.links.new(set_position.outputs[0], remove.inputs[0])
    tree.links.new(remove.outputs[0], tree.node("NodeGroupOutput").inputs[0])
    return group


def measure(ring, rings):
    from kodawari.fish import route

    bpy.ops.wm.read_homefile(use_empty=True)
    scene = bpy.context.scene
    scene.render.fps = 24
    frames = list(range(1, FRAMES + 2))
    fish = bench_fish.build_side("kodawari", scene, ring, rings)
    handler = bench_fish.detach_frame_handler()  # the copies are driven here
    try:
        rig, tables = bench_fish.frame_tables(fish, scene, frames)
        swim = route.modifier(fish).node_group
        table_obj = swim.nodes["frames"].inputs[0].default_value
        computed = swim.get("kodawari_stored") == "s"  # u and v from Position: matrix applies

        def write(frame):
            route.write_frame(fish, tables[frame], None)

        kinds = ["pass", "multiply_add", "vector_madd", "add", "sample1", "sample6"]
        kinds += ["transform"] if MATRICES else []
        trees = {kind: (lambda k=kind: new_group(k, table_obj, chain(k)), write) for kind in kinds}
        trees["fish_swim"] = (lambda: swim, write)
        if MATRICES and computed:
            matrix_mesh = bpy.data.meshes.new(".bench matrix rows")
            matrix_mesh.vertices.add(route.ROWS)
            for name in ("A", "dA"):
                matrix_mesh.attributes.new(name, "FLOAT4X4", "POINT")
            matrix_obj = bpy.data.objects.new(".bench matrix rows", matrix_mesh)
            buffer = np.empty((2, route.ROWS, 16), np.float32)
            rows = {f: matrix_rows(tables[f], rig.affine_rows, buffer).copy() for f in frames}

            def write_matrix(frame):
                for k, name in enumerate(("A", "dA")):
                    attribute = matrix_mesh.attributes[name]
                    attribute.data.foreach_set("value", rows[frame][k].reshape(-1))
                matrix_mesh.update_tag()

            trees["matrix"] = (lambda: new_group("matrix", matrix_obj, matrix_group), write_matrix)
        copies = {}
        for kind, (make, writer) in trees.items():
            copies[kind] = (*bench_fish.copy_in_own_scene(fish, kind, make()), writer)
        # Same shape: the matrix tree against the Fish Swim tree, at one frame.
        shapes = {}
        for kind in ("fish_swim", "matrix"):
            if kind in copies:
                part_scene, obj, writer = copies[kind]
                writer(3)
                depsgraph = part_scene.view_layers[0].depsgraph
                depsgraph.update()
                evaluated = obj.evaluated_get(depsgraph).data
                co = np.empty(len(evaluated.vertices) * 3, np.float32)
                evaluated.vertices.foreach_get("co", co)
                shapes[kind] = co
        matrix_error = (
            float(np.abs(shapes["matrix"] - shapes["fish_swim"]).max())
            if "matrix" in shapes
            else None
        )

        def player(kind):
            part_scene, obj, writer = copies[kind]
            depsgraph = part_scene.view_layers[0].depsgraph

            def play(_round):
                writer(1)
                depsgraph.update()
                seconds = []
                for frame in frames[1:]:
                    start = time.perf_counter()
                    writer(frame)
                    depsgraph.update()
                    obj.evaluated_get(depsgraph)
                    seconds.append(time.perf_counter() - start)
                return seconds

            return play

        rows = benchlib.Rounds(rounds=5).run({kind: player(kind) for kind in copies})
    finally:
        bpy.app.handlers.frame_change_post.append(handler)
    return rows, matrix_error


def main():
    print(
        f"=== fish, what the Fish Swim tree's nodes cost ({benchlib.blender_label()}, "
        f"{os.cpu_count()} CPUs, load {benchlib.load()}): wall ms per frame (helper write +"
        f" evaluation, no normals), min / median of 5 rounds of {FRAMES} frames"
    )
    results = []
    for ring, rings in benchlib.sizes(SIZES).values():
        rows, matrix_error = measure(ring, rings)
        vertices = ring * rings
        base = rows["pass"]["ms_median"]
        print(f"  {vertices:>9,} vertices:")
        for kind, row in rows.items():
            print(f"    {kind:15s} {benchlib.fmt_ms(row)}  load {row['load']:4.1f}")
        per_node = {
            kind: (rows[kind]["ms_median"] - base) / 4 * 1e6 / vertices
            for kind in ("multiply_add", "vector_madd", "add", "transform")
            if kind in rows
        }
        add = per_node["add"]
        per_node["sample"] = (
            (rows["sample6"]["ms_median"] - rows["sample1"]["ms_median"]) * 1e6 / vertices - 5 * add
        ) / 5
        print(
            "    ns per vertex per node (median - pass): "
            + ", ".join(f"{kind} {ns:.2f}" for kind, ns in per_node.items())
        )
        if "matrix" in rows:
            print(
                f"    matrix tree / Fish Swim tree: "
                f"{rows['matrix']['ms_median'] / rows['fish_swim']['ms_median']:.2f}x;"
                f" positions at most {matrix_error:.2g} apart"
            )
        results.append(
            {
                "vertices": vertices,
                "rows": rows,
                "ns_per_vertex_per_node": {k: round(v, 3) for k, v in per_node.items()},
                "matrix_max_difference": matrix_error,
            }
        )
    benchlib.record("fish_nodes", results)


if __name__ == "__main__":
    main()
