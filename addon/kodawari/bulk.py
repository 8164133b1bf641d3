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
    if out is None:  # len() walks the whole bone list in 3.4: callers per frame pass `out`
        out = np.empty((len(pose_bones), 4, 4), dtype=np.float32)
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


# Pose-bone rotations without RNA, for Blender 4.x, where a foreach_set on the original pose
# runs the RNA update: it tags the armature object and Blender then copies the whole object
# (every pose channel) in the coming evaluation, 4.5-8.4x a bare evaluation at 160-16,000 bones
# (docs/algorithms.md §3.7). A bPoseChannel (DNA_action_types.h) keeps
#   loc[3], size[3], eul[3], quat[4], rotAxis[3], rotAngle
# one after the other (2.8 through 5.0). The offset of that run is found by matching those 17
# floats against RNA on a few channels; a view is refused (None) when they disagree.
# Searched from the channel's start; within the struct (loc[0] is at byte 252 in 4.5 and 5.0).
_POSE_CHANNEL_SEARCH_BYTES = 512
_POSE_CHANNEL_QUAT = 9  # floats from loc[0] to quat[0]
_POSE_VIEW_MAX_SPAN = 1 << 36  # bytes between the first and last channel a view may cover


# After Blender evaluates a pose in the viewport's (active) depsgraph it copies every evaluated
# bone's pose matrix back into the original channel (pose_mat, float[4][4], the layout
# foreach_get("matrix") gives): reading it there, without RNA, tells which bones a pass
# evaluated at ~0.01 µs a bone instead of ~0.1 through foreach_get (docs/algorithms.md §3.7).
# Its offset is found by matching PoseBone.matrix, within the same search window.
_POSE_MATRIX_FLOATS = 16


def _pose_channel_floats(pose_bone):
    """The 17 floats of loc, size, eul, quat, rotAxis, rotAngle as RNA gives them."""
    angle, *axis = pose_bone.rotation_axis_angle
    values = (
        tuple(pose_bone.location)
        + tuple(pose_bone.scale)
        + tuple(pose_bone.rotation_euler)
        + tuple(pose_bone.rotation_quaternion)
        + tuple(axis)
        + (angle,)
    )
    return np.array(values, np.float32)


def _runs_matching(pose_bone, want):
    """Float indices in this bone's bPoseChannel (its first _POSE_CHANNEL_SEARCH_BYTES) where
    the float32 run `want` lies, in order; empty without an address."""
    import ctypes

    address = pose_bone.as_pointer()
    if not address:
        return np.empty(0, np.int64)
    memory = np.frombuffer(ctypes.string_at(address, _POSE_CHANNEL_SEARCH_BYTES), np.float32)
    windows = np.lib.stride_tricks.sliding_window_view(memory, len(want))
    return np.flatnonzero(np.all(windows == want, axis=1))


def _quat_offset(pose_bone):
    """Byte offset of quat[0] in this bone's bPoseChannel, or None."""
    found = _runs_matching(pose_bone, _pose_channel_floats(pose_bone))
    # The first match: a later one may be the next channel in memory (a bone at rest looks
    # like any other); the offsets of three channels must agree (PoseRotationView.create).
    return None if not len(found) else int(found[0] + _POSE_CHANNEL_QUAT) * 4


def _matrix_offsets(pose_bone):
    """Byte offsets in this bone's bPoseChannel where its pose matrix (16 floats) lies."""
    want = np.array(pose_bone.matrix, np.float32).T.reshape(-1)
    return {int(i) * 4 for i in _runs_matching(pose_bone, want)}


class PoseRotationView:
    """rotation_quaternion of some original pose bones, read and written in Blender's memory
    without RNA (no update runs, nothing is tagged: the caller writes the evaluated copy too,
    or tags). Built once per armature runtime; valid while the pose's channels are the ones it
    was built on. `current` checks that from the pose's channel list (bPose starts with the
    ListBase chanbase {first, last}; a bone added, even with another removed, appends a new
    channel), and the caller compares a read with RNA's before writing."""

    def __init__(
        self, indices, offset, addresses, pose_address, first, last, names, matrix_offset=None
    ):
        import ctypes

        base = int(addresses.min())
        end = offset + 16 if matrix_offset is None else max(offset + 16, matrix_offset + 64)
        span = int(addresses.max()) - base + end
        self.indices = indices
        self.pose = (pose_address, first, last)
        self.names = names  # of the first and last bone, for agrees()
        memory = (ctypes.c_float * (span // 4)).from_address(base)
        self.memory = np.frombuffer(memory, np.float32)
        self.index = ((addresses - base + offset) // 4).astype(np.int64)[:, None] + np.arange(4)
        self.matrix_index = None  # flat indices of every bone's pose matrix, when found
        if matrix_offset is not None:
            rows = ((addresses - base + matrix_offset) // 4).astype(np.int64)
            self.matrix_index = (rows[:, None] + np.arange(_POSE_MATRIX_FLOATS)).reshape(-1)

    @staticmethod
    def _chanbase(pose):
        import ctypes

        address = pose.as_pointer()
        first, last = (ctypes.c_void_p * 2).from_address(address)
        return address, first, last

    @classmethod
    def create(cls, pose, indices):
        """A view of pose.bones[indices]' rotations, or None where the layout is not confirmed
        (checked on the first, middle and last of them) or the channels lie too far apart."""
        indices = np.asarray(indices, np.int64)
        if not len(indices) or bpy.app.version >= (5, 1, 0) or pose.id_data.library:
            return None  # linked data is not written behind RNA's back
        pose_bones = list(pose.bones)  # one walk of the channel list
        samples = {int(indices[0]), int(indices[len(indices) // 2]), int(indices[-1])}
        offsets = {_quat_offset(pose_bones[i]) for i in samples}
        if len(offsets) != 1 or None in offsets:
            return None
        offset = offsets.pop()
        # The pose matrix where all three agree on exactly one place past the rotation (a bone
        # whose local and pose matrices coincide could match twice: then no matrices, RNA reads).
        matrix = set.intersection(*(_matrix_offsets(pose_bones[i]) for i in samples))
        matrix = {m for m in matrix if m >= offset + 16}
        matrix_offset = matrix.pop() if len(matrix) == 1 else None
        every = np.array([pb.as_pointer() for pb in pose_bones], np.int64)
        addresses = every[indices]
        if addresses.min() <= 0 or addresses.max() - addresses.min() > _POSE_VIEW_MAX_SPAN:
            return None
        chanbase = cls._chanbase(pose)
        if chanbase[1:] != (int(every[0]), int(every[-1])):
            return None
        names = (pose_bones[int(indices[0])].name, pose_bones[int(indices[-1])].name)
        view = cls(indices, offset, addresses, *chanbase, names, matrix_offset)
        # A few channels by name and address, for same_channels().
        view.samples = [
            (pose_bones[int(i)].name, int(every[i]))
            for i in indices[np.linspace(0, len(indices) - 1, 5).astype(np.int64)]
        ]
        return view

    def same_channels(self, pose):
        """True when five of the view's bones (first, last and between, by name) are still at the
        addresses the view was built on: a pose copied afresh (an evaluated copy, copied again
        by Blender) could by chance get back its first and last channels' addresses, hardly all
        five. A check for views of memory Blender replaces often, on top of current()."""
        for name, address in self.samples:
            pose_bone = pose.bones.get(name)
            if pose_bone is None or pose_bone.as_pointer() != address:
                return False
        return True

    def current(self, pose):
        """False once the pose or its channel list changed (a bone added or removed)."""
        return self._chanbase(pose) == self.pose

    def agrees(self, pose):
        """True when the first and last bone's rotations read here are RNA's (a name lookup is
        hashed, an index one walks the list)."""
        view = self.memory[self.index[[0, -1]]]
        for row, name in zip(view, self.names):
            pose_bone = pose.bones.get(name)
            if pose_bone is None or tuple(row) != tuple(
                np.float32(c) for c in pose_bone.rotation_quaternion
            ):
                return False
        return True

    def read(self):
        """(N, 4) float32 copy of the rotations."""
        return self.memory[self.index]

    def write(self, rotations):
        """rotations (B, 4) float32 for every bone; the view's bones are written."""
        self.memory[self.index] = rotations[self.indices]

    def write_rows(self, rows):
        """rows (N, 4) float32, one a view's bone (rotations[indices], already gathered)."""
        self.memory[self.index] = rows

    def read_matrices(self, rows):
        """The pose matrices of the view's bones at `rows` (indices into `indices`) as Blender's
        last evaluation in the viewport's depsgraph left them: float32 (len(rows), 16) in
        foreach_get's layout; None when the matrices were not found."""
        if self.matrix_index is None:
            return None
        return self.memory.take(self.matrix_index.reshape(-1, _POSE_MATRIX_FLOATS)[rows])


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
