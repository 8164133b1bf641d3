"""Bulk data movement between Blender and contiguous NumPy arrays.

One foreach_get/foreach_set per array: never a Python loop per vertex or bone.
"""

import bpy
import numpy as np


def vertex_positions(mesh, out=None):
    """Rest positions of a mesh's vertices as float32 (N, 3)."""
    n = len(mesh.vertices)
    if out is None:
        out = np.empty((n, 3), dtype=np.float32)
    mesh.vertices.foreach_get("co", out.reshape(-1))
    return out


def _shape_key_points(key_block):
    # ShapeKey.points (4.1+) has the raw-array fast path: ~2 ns per vertex
    # against ~140 through ShapeKey.data, whose item type is not fixed.
    return getattr(key_block, "points", None) or key_block.data


def shape_key_positions(key_block, out=None):
    n = len(key_block.data)
    if out is None:
        out = np.empty((n, 3), dtype=np.float32)
    _shape_key_points(key_block).foreach_get("co", out.reshape(-1))
    return out


def set_shape_key_positions(key_block, positions):
    """Write float32 (N, 3) into a shape key and tag its mesh for re-evaluation."""
    _shape_key_points(key_block).foreach_set(
        "co", np.ascontiguousarray(positions, dtype=np.float32).reshape(-1)
    )
    key_block.id_data.user.update_tag()


def set_vertex_positions(mesh, positions):
    mesh.vertices.foreach_set("co", np.ascontiguousarray(positions, dtype=np.float32).reshape(-1))
    mesh.update()


def vertex_group_weights(obj, group_name):
    """Weights (float32, N) of one vertex group; 0 where a vertex is not in it.

    Blender offers no foreach access to vertex groups, so this walks the
    vertices once in Python; it runs at set-up time only, never per frame.
    """
    group = obj.vertex_groups[group_name]
    index = group.index
    mesh = obj.data
    weights = np.zeros(len(mesh.vertices), dtype=np.float32)
    for vertex in mesh.vertices:
        for element in vertex.groups:
            if element.group == index:
                weights[vertex.index] = element.weight
                break
    return weights


def pose_bone_matrices(pose_bones, out=None):
    """Armature-space 4x4 matrices of pose bones as float32 (B, 4, 4), row-major."""
    n = len(pose_bones)
    if out is None:
        out = np.empty((n, 4, 4), dtype=np.float32)
    pose_bones.foreach_get("matrix", out.reshape(-1))
    # foreach_get yields Blender's column-major matrix layout.
    return out.transpose(0, 2, 1)


def pose_rotations(pose_bones, out):
    """Every pose bone's rotation_quaternion into float32 (B, 4) `out`."""
    pose_bones.foreach_get("rotation_quaternion", out.reshape(-1))
    return out


# Blender 4.x runs the RNA update after a foreach_set on pose bones: the armature object is
# tagged and its evaluated copy made afresh at the next evaluation (measured in 4.5 and 5.0;
# 3.4 tags nothing, and a write then reaches only the original until something tags it).
POSE_WRITE_TAGS = bpy.app.version >= (4, 0, 0)


def set_pose_rotations(pose_bones, rotations):
    """Writes float32 (B, 4) into every pose bone's rotation_quaternion (see POSE_WRITE_TAGS);
    the caller tags what must be evaluated again."""
    pose_bones.foreach_set("rotation_quaternion", rotations.reshape(-1))


# Shape key data without RNA. A KeyBlock keeps its positions in one float array;
# DNA_key_types.h lays out KeyBlock as
#   next, prev (2 pointers) | pos, curval (float) | type, pad, relative, flag (short) |
#   totelem (int, offset 32) | uid (int) | data (pointer, offset 40)
# in Blender 2.8 through 5.0 (checked in 3.4.1, 4.5 and 5.0.1). The layout is checked against
# RNA before every use (element count, first and last positions); any mismatch means None and
# the callers go through foreach_set. Before 4.1 RNA has no raw path for ShapeKeyPoint
# (foreach_set ~90 ns per vertex: a 1 M-vertex key ~90 ms); from 4.1 ShapeKey.points has one,
# but writing in place still saves the caller's own (N, 3) buffer and one copy per frame.
_KEYBLOCK_TOTELEM_OFFSET = 32
_KEYBLOCK_DATA_OFFSET = 40
_KEYBLOCK_LAYOUT_VERSIONS = ((2, 80, 0), (5, 1, 0))


def _shape_key_view(key_block, count):
    import ctypes

    address = key_block.as_pointer()
    if not address or ctypes.c_int.from_address(address + _KEYBLOCK_TOTELEM_OFFSET).value != count:
        return None
    data = ctypes.c_void_p.from_address(address + _KEYBLOCK_DATA_OFFSET).value
    if not data:
        return None
    # frombuffer: numpy's own float32 dtype (the native module checks dtype identity)
    view = np.frombuffer((ctypes.c_float * (3 * count)).from_address(data), np.float32)
    view = view.reshape(count, 3)
    first, last = key_block.data[0].co, key_block.data[count - 1].co
    if tuple(view[0]) != tuple(np.float32(c) for c in first) or tuple(view[-1]) != tuple(
        np.float32(c) for c in last
    ):
        return None
    return view


def shape_key_view(key_block):
    """A writable float32 (N, 3) view of the shape key's positions in Blender's own memory, or
    None where the layout above cannot be confirmed. Valid until the key changes (Edit Mode,
    a removed key): take it again for every write, never keep it. After writing, tag_shape_key."""
    if not _KEYBLOCK_LAYOUT_VERSIONS[0] <= bpy.app.version < _KEYBLOCK_LAYOUT_VERSIONS[1]:
        return None
    count = len(key_block.data)
    return _shape_key_view(key_block, count) if count else None


def tag_shape_key(key_block):
    """Tell Blender a shape key's positions changed (see write_shape_key_positions: the Key only)."""
    key_block.id_data.update_tag()


def write_shape_key_positions(key_block, positions):
    """Write float32 (N, 3) into a shape key (memory copy when the layout checks out) and
    tag the Key for re-evaluation; returns True when the fast path was used.

    Only the Key is tagged, not its Mesh: the tag flushes to the mesh's geometry (the shape
    keys are mixed again, normals recomputed, modifiers re-run), while a Mesh tag also made
    Blender re-copy the whole mesh every frame. Same evaluated positions and normals; at 1 M
    vertices ~10 % cheaper per whole frame in 3.4 and 4.5 (tests/bench, issue 13)."""
    count = len(key_block.data)
    positions = np.ascontiguousarray(positions, dtype=np.float32)
    # Only where RNA has no raw path (before 4.1) and the layout above is known to hold;
    # 4.1+ writes through ShapeKey.points at the same speed without touching memory.
    raw_ok = _KEYBLOCK_LAYOUT_VERSIONS[0] <= bpy.app.version < (4, 1, 0)
    view = (
        _shape_key_view(key_block, count)
        if raw_ok and count and positions.shape == (count, 3)
        else None
    )
    if view is None:
        _shape_key_points(key_block).foreach_set("co", positions.reshape(-1))
    else:
        np.copyto(view, positions)
    tag_shape_key(key_block)
    return view is not None
