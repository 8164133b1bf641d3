"""Shared set-up for the fish swim tests: procedural fish from blend_samples/fish_shapes.py."""

import os
import sys

import bpy  # first: puts Blender's own modules (bmesh) on sys.path

# isort: split
import bmesh
import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "blend_samples"))
import fish_shapes
import smooth_fish  # noqa: F401  (re-exported for the tests)

FIN_KIND = {
    "fin_dorsal": "DORSAL",
    "fin_anal": "ANAL",
    "fin_pectoral": "PECTORAL",
    "fin_caudal": "CAUDAL",
}
SHAPE_KEY = "Kodawari Swim"


def make_fish(kind="tuna", head_axis="POS_X", **kwargs):
    obj = fish_shapes.build_fish(kind, head_axis=head_axis, **kwargs)
    activate(obj)
    return obj


def activate(obj):
    for other in bpy.context.view_layer.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    obj.select_set(True)


def add_swim(obj, fins=(), **kwargs):
    activate(obj)
    assert bpy.ops.kodawari.swim_add(**kwargs) == {"FINISHED"}
    for group in fins:
        assert bpy.ops.kodawari.swim_fin_add(vertex_group=group, kind=FIN_KIND[group]) == {
            "FINISHED"
        }
    return obj.kodawari_swim


def rest(obj):
    out = np.empty((len(obj.data.vertices), 3), dtype=np.float32)
    obj.data.vertices.foreach_get("co", out.reshape(-1))
    return out


def live(obj):
    """The swimming positions Blender shows: the evaluated mesh (the Fish Swim modifier
    comes first in the stack)."""
    return evaluated(obj)


def frames(obj, frame_list):
    """Live positions (F, N, 3) at each frame."""
    scene = bpy.context.scene
    out = []
    for frame in frame_list:
        scene.frame_set(frame)
        out.append(live(obj).copy())
    return np.array(out)


def evaluated(obj):
    """Positions after modifiers (what renders and exports see)."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    mesh = obj.evaluated_get(depsgraph).to_mesh()
    try:
        out = np.empty((len(mesh.vertices), 3), dtype=np.float32)
        mesh.vertices.foreach_get("co", out.reshape(-1))
    finally:
        obj.evaluated_get(depsgraph).to_mesh_clear()
    return out


def group_mask(obj, name):
    index = obj.vertex_groups[name].index
    mask = np.zeros(len(obj.data.vertices), dtype=bool)
    for v in obj.data.vertices:
        if any(g.group == index for g in v.groups):
            mask[v.index] = True
    return mask


def fin_mask(obj):
    mask = np.zeros(len(obj.data.vertices), dtype=bool)
    for group in obj.vertex_groups:
        mask |= group_mask(obj, group.name)
    return mask


def body_length(obj, axis=0):
    co = rest(obj)
    return float(co[:, axis].max() - co[:, axis].min())


def set_fps(fps=24):
    scene = bpy.context.scene
    scene.render.fps = fps
    scene.render.fps_base = 1.0
    scene.frame_start = 1


def spindle_with_a_mouth(name="spindle", segments=64, rings=48):
    """A smooth body of revolution-like fish along +X (an ellipsoid 1 long, wider than high)
    with a mouth slit pushed into its snout, the same above and below and on both sides:
    its mid-line, and so its rest axis, is straight."""
    mesh = bpy.data.meshes.new(name)
    bm = bmesh.new()
    bmesh.ops.create_uvsphere(bm, u_segments=segments, v_segments=rings, radius=1.0)
    bm.to_mesh(mesh)
    bm.free()
    co = np.empty((len(mesh.vertices), 3), dtype=np.float32)
    mesh.vertices.foreach_get("co", co.reshape(-1))
    co = co.astype(np.float64)
    co = np.stack([co[:, 2] * 0.5, co[:, 1] * 0.08, -co[:, 0] * 0.1], axis=1)  # poles on X
    mouth = (co[:, 0] > 0.46) & (np.abs(co[:, 2]) < 0.03)
    co[mouth, 0] -= 0.05 * (1.0 - np.abs(co[mouth, 2]) / 0.03)  # the slit, deepest at its middle
    mesh.vertices.foreach_set("co", co.astype(np.float32).reshape(-1))
    mesh.polygons.foreach_set("use_smooth", np.ones(len(mesh.polygons), bool))
    mesh.update()
    obj = bpy.data.objects.new(name, mesh)
    bpy.context.scene.collection.objects.link(obj)
    return obj
