"""The per-frame write path (bulk.write_shape_key_positions): what the user sees after it is the
new shape, with fresh normals, even when the viewport already read the previous frame's normals."""

import bpy
import numpy as np


def _vertex_normals(mesh):
    normals = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("normal", normals)
    return normals.reshape(-1, 3)


def _evaluated(obj):
    depsgraph = bpy.context.evaluated_depsgraph_get()
    depsgraph.update()
    mesh = obj.evaluated_get(depsgraph).data
    co = np.empty(len(mesh.vertices) * 3, np.float32)
    mesh.vertices.foreach_get("co", co)
    return co.reshape(-1, 3), _vertex_normals(mesh)


def _reference_normals(obj, positions):
    """Normals of a plain mesh (no shape keys) with the same faces at `positions`."""
    faces = [tuple(p.vertices) for p in obj.data.polygons]
    mesh = bpy.data.meshes.new("reference")
    mesh.from_pydata(positions.tolist(), [], faces)
    mesh.update()
    try:
        return _vertex_normals(mesh)
    finally:
        bpy.data.meshes.remove(mesh)


def test_a_written_shape_key_reaches_the_evaluated_mesh_with_fresh_normals(empty_scene):
    from kodawari import bulk

    bpy.ops.mesh.primitive_uv_sphere_add(segments=32, ring_count=16, radius=1.0)
    obj = bpy.context.active_object
    rest = bulk.vertex_positions(obj.data)
    obj.shape_key_add(name="Basis")
    block = obj.shape_key_add(name="Swim")
    block.value = 1.0

    squashed = rest * np.array([1.0, 1.0, 0.3], np.float32)
    bulk.write_shape_key_positions(block, squashed)
    seen, normals = _evaluated(obj)  # the viewport reads this frame's normals: they are cached now
    np.testing.assert_allclose(seen, squashed, atol=1e-6)

    bent = rest.copy()
    bent[:, 2] += 0.8 * rest[:, 0] ** 2  # a different shape: most normals turn
    bulk.write_shape_key_positions(block, bent)
    seen, normals = _evaluated(obj)
    np.testing.assert_allclose(seen, bent, atol=1e-6)
    expected = _reference_normals(obj, bent)
    assert np.abs(normals - expected).max() < 1e-4
    # and the original holds the shape too (saved with the file, read by the bake)
    np.testing.assert_array_equal(bulk.shape_key_positions(block), bent)
