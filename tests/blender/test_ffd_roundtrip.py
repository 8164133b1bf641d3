"""The FFD core inside Blender: a mesh read with bulk.py, bent by kodawari_native,
written back into a shape key, and seen bent in the evaluated mesh."""

import bpy
import numpy as np


def _tube(scene):
    bpy.ops.mesh.primitive_cylinder_add(
        vertices=24, depth=4.0, radius=0.3, location=(2.0, 0.0, 0.0), rotation=(0.0, np.pi / 2, 0.0)
    )
    obj = bpy.context.active_object
    bpy.ops.object.transform_apply(location=True, rotation=True, scale=True)
    return obj


def test_bent_positions_reach_the_evaluated_mesh_through_a_shape_key(empty_scene):
    from kodawari import bulk, native

    kn = native.module()
    obj = _tube(empty_scene)
    rest = bulk.vertex_positions(obj.data)
    axis = np.column_stack([np.linspace(0.0, 4.0, 6), np.zeros(6), np.zeros(6)])
    binding = kn.ffd_bind(axis, rest)

    out = np.empty_like(rest)
    binding.deform(axis, out)
    np.testing.assert_allclose(out, rest, atol=1e-5 * 4.0)  # at rest nothing moves

    bent = axis.copy()
    bent[:, 1] = 0.5 * np.linspace(0, 1, 6) ** 2
    bent = kn.preserve_lengths_from_head(
        bent, np.linalg.norm(np.diff(axis, axis=0), axis=1), arc_length=kn.curve_length(axis)
    )
    binding.deform(bent, out)
    obj.shape_key_add(name="Basis")
    key = obj.shape_key_add(name="kodawari_ffd")
    key.value = 1.0
    bulk.set_shape_key_positions(key, out)
    np.testing.assert_array_equal(bulk.shape_key_positions(key), out)

    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    evaluated = obj.evaluated_get(depsgraph).data
    seen = bulk.vertex_positions(evaluated)
    np.testing.assert_allclose(seen, out, atol=1e-6)
    assert seen[:, 1].max() > 0.5  # the tail end really swung sideways
    # The cross-section stays rigid: every vertex keeps its distance to the axis.
    t = binding.t.astype(np.float64)
    inside = binding.w == 0
    rest_radius = np.linalg.norm(rest - kn.curve_points(axis, t), axis=1)[inside]
    bent_radius = np.linalg.norm(seen - kn.curve_points(bent, t), axis=1)[inside]
    np.testing.assert_allclose(bent_radius, rest_radius, atol=1e-4)
