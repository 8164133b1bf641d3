"""A synthetic armature for rod tests without Blender: bone 0 is the head (the
kinematic parent and reference), bones 1..n a straight chain along the head's +Y
starting at `root_offset`; matrices are packed as pose.bones.foreach_get("matrix") does."""

import kodawari_native as kn
import numpy as np


def no_keys():
    """add_rod's key arguments for a rod with no view, pose or speed keys."""
    return dict(
        key_conditions=np.zeros(0, np.int32),
        key_directions=np.zeros((0, 3)),
        key_rotations=np.zeros((0, 4)),
        key_speeds=np.zeros(0),
        key_influences=np.zeros(0),
        key_shapes=np.zeros((0, 4)),
    )


def quat_to_matrix(q):
    w, x, y, z = q / np.linalg.norm(q)
    return np.array(
        [
            [1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)],
            [2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)],
            [2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)],
        ]
    )


def axis_angle_quat(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    return np.array([np.cos(angle / 2), *(np.sin(angle / 2) * axis)])


def pack_matrices(rotations, positions):
    """(B, 3, 3) rotations and (B, 3) positions -> (B, 16) float32, column-major per bone."""
    m = np.zeros((len(rotations), 4, 4))
    m[:, :3, :3] = rotations
    m[:, :3, 3] = positions
    m[:, 3, 3] = 1
    return np.ascontiguousarray(m.transpose(0, 2, 1).reshape(-1, 16), dtype=np.float32)


class Chain:
    def __init__(
        self,
        bones=6,
        length=0.1,
        root_offset=(0.0, 0.2, 0.0),
        keys=(),
        threads=0,
        colliders=None,
        momentum_control=True,
        **params,
    ):
        self.n = bones
        self.length = length
        self.bone_count = bones + 1
        self.system = kn.RodSystem(self.bone_count, threads)
        offsets = np.array([root_offset] + [(0.0, length, 0.0)] * bones, dtype=np.float64)
        rest = np.tile([1.0, 0, 0, 0], (bones, 1))
        conditions = np.array([k["condition"] for k in keys], dtype=np.int32)
        m = len(keys)
        directions = np.array(
            [k.get("direction", (0, 1, 0)) for k in keys], dtype=np.float64
        ).reshape(m, 3)
        rotations = np.array(
            [k.get("rotation", (1, 0, 0, 0)) for k in keys], dtype=np.float64
        ).reshape(m, 4)
        speeds = np.array([k.get("speed", 0.0) for k in keys], dtype=np.float64)
        influences = np.array([k.get("influence", 2.4) for k in keys], dtype=np.float64)
        shapes = np.array([k["shape"] for k in keys], dtype=np.float64).reshape(m * bones, 4)
        params.setdefault("wind", np.zeros(3))
        self.rod = self.system.add_rod(
            0,
            0,
            np.arange(1, bones + 1, dtype=np.int32),
            offsets,
            rest,
            key_conditions=conditions,
            key_directions=directions,
            key_rotations=rotations,
            key_speeds=speeds,
            key_influences=influences,
            key_shapes=shapes,
            momentum_control=momentum_control,
            **params,
        )
        if colliders is not None:
            self.system.set_colliders(*colliders)
        self.head_rotation = np.eye(3)
        self.head_position = np.zeros(3)
        self.out = np.zeros((self.bone_count, 4), dtype=np.float32)
        self.out[:, 0] = 1
        self.time = 0.0

    def matrices(self):
        rotations = np.tile(np.eye(3), (self.bone_count, 1, 1))
        positions = np.zeros((self.bone_count, 3))
        rotations[0] = self.head_rotation
        positions[0] = self.head_position
        return pack_matrices(rotations, positions)

    def reset(self, camera=None, gravity=(0, 0, -9.81)):
        self.system.reset(
            self.matrices(),
            np.eye(4),
            None if camera is None else np.asarray(camera, float),
            np.asarray(gravity, float),
            self.time,
            self.out,
        )

    def step(self, camera=None, gravity=(0, 0, -9.81), dt=1 / 24):
        self.time += dt
        self.system.step(
            self.matrices(),
            np.eye(4),
            None if camera is None else np.asarray(camera, float),
            np.asarray(gravity, float),
            self.time,
            dt,
            self.out,
        )
        return self.out

    def positions(self):
        return self.system.joint_positions(self.rod)

    def rest_positions(self, shape_quats):
        """Joint positions of a shape by forward kinematics under the current head."""
        frame = self.head_rotation.copy()
        head = self.head_position + self.head_rotation @ np.array([0.0, 0.2, 0.0])
        points = [head]
        for q in shape_quats:
            frame = frame @ quat_to_matrix(np.asarray(q, float))
            head = head + frame @ np.array([0.0, self.length, 0.0])
            points.append(head)
        return np.array(points)
