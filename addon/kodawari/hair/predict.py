"""A new frame's solver inputs, known before Blender evaluates the frame (docs/algorithms.md §3.7).

The rods read the armature-space matrices of their parent, reference and collider bones, the
armature's world matrix and the camera's position. When those are moved only by what can be
evaluated exactly here — the objects' own action F-curves (`FCurve.evaluate`, Blender's own
evaluation), the bones' rest matrices, channels and inherit flags (forward kinematics in the
native core) — the frame can be solved and written in `frame_change_pre`, so Blender evaluates
it once. Anything else (constraints, drivers, NLA, parents, rigid bodies, animated rotation
modes, inherit-scale modes not modelled) makes `PosePredictor` refuse, and the frame takes the
post-evaluation path. The prediction is checked against Blender's evaluation after the pass
(`matches`); a wrong one is thrown away and solved again from the true inputs.
"""

import operator
import re

import numpy as np

from .. import fcurves, native

# Blender's rotation-mode numbering (the native forward kinematics speaks it).
ROTATION_MODES = {
    "QUATERNION": 0,
    "XYZ": 1,
    "XZY": 2,
    "YXZ": 3,
    "YZX": 4,
    "ZXY": 5,
    "ZYX": 6,
    "AXIS_ANGLE": -1,
}
INHERIT_SCALE = {"FULL": 0, "AVERAGE": 1, "NONE": 2, "NONE_LEGACY": 3}
# A prediction holds when every input is within this of Blender's (relative above 1): Blender
# evaluates in float32 (about 1e-7 relative), the native forward kinematics in float64.
TOLERANCE = 1e-6
_CONSTRAINTS = operator.attrgetter("constraints")
_BONE_PATH = re.compile(r'^pose\.bones\["((?:[^"\\]|\\.)*)"\]\.(\w+)$')
# Pose-bone channels: (property, first column in the channel row, value count).
_BONE_CHANNELS = {
    "location": (0, 3),
    "rotation_quaternion": (3, 4),
    "rotation_euler": (3, 3),
    "rotation_axis_angle": (3, 4),
    "scale": (7, 3),
}
_ROTATION_PROPERTY = {"QUATERNION": "rotation_quaternion", "AXIS_ANGLE": "rotation_axis_angle"}
_OBJECT_CHANNELS = (
    "location",
    "rotation_euler",
    "rotation_quaternion",
    "rotation_axis_angle",
    "scale",
)
_OBJECT_DELTAS = (
    "delta_location",
    "delta_rotation_euler",
    "delta_rotation_quaternion",
    "delta_scale",
)


class Unpredictable(Exception):
    """The inputs depend on something this module does not evaluate; the message says what."""


def _unescape(name):
    return re.sub(r"\\(.)", r"\1", name)


def _rotation_property(mode):
    return _ROTATION_PROPERTY.get(mode, "rotation_euler")


def _evaluated_curves(id_block, what):
    """The F-curves Blender applies to id_block at any frame, when the action alone animates
    it (no NLA, full influence, replace); drivers are checked by _refuse_drivers."""
    anim = id_block.animation_data
    if anim is None:
        return []
    if len(anim.nla_tracks) or anim.use_tweak_mode:
        raise Unpredictable(f"{what} uses the NLA")
    if anim.action is None:
        return []
    if anim.action_blend_type != "REPLACE" or anim.action_influence != 1.0:
        raise Unpredictable(f"{what} blends its action")
    return [
        fc
        for fc in fcurves.action_fcurves(anim.action, id_block)
        if not fc.mute and fc.is_valid and not (fc.group is not None and fc.group.mute)
    ]


def _refuse_drivers(id_block, what, bones=None):
    """Raises when a driver of id_block can move what the rods read: the object's own
    transform (or rotation mode), or any property of the pose bones named in `bones`. Drivers
    of other bones and of custom properties move nothing the rods read."""
    anim = id_block.animation_data
    if anim is None:
        return
    for driver in anim.drivers:
        if driver.mute:
            continue
        match = _BONE_PATH.match(driver.data_path)
        if match is not None:
            if bones is not None and _unescape(match.group(1)) in bones:
                raise Unpredictable(f"{what} has a driver on {driver.data_path}")
        elif driver.data_path in _OBJECT_CHANNELS + _OBJECT_DELTAS + ("rotation_mode",):
            raise Unpredictable(f"{what} has a driver on {driver.data_path}")


# Constraints that turn an object without moving it: a camera aimed by one still has the
# position its own channels give (the rods read only the camera's position).
_AIMING = {"TRACK_TO", "DAMPED_TRACK", "LOCKED_TRACK"}


class ObjectMotion:
    """An object's world matrix from its own transform channels (no parent, no constraints;
    with position_only, aiming constraints are allowed and only position() is valid)."""

    def __init__(self, obj, what, position_only=False):
        if obj.parent is not None:
            raise Unpredictable(f"{what} has a parent")
        allowed = _AIMING if position_only else set()
        if any(c.type not in allowed for c in obj.constraints if c.enabled):
            raise Unpredictable(f"{what} has constraints")
        if getattr(obj, "rigid_body", None) is not None:
            raise Unpredictable(f"{what} is a rigid body")
        _refuse_drivers(obj, what)
        self.obj = obj
        self.curves = []  # (property, index, fcurve)
        for fc in _evaluated_curves(obj, what):
            if fc.data_path in _OBJECT_DELTAS or fc.data_path == "rotation_mode":
                raise Unpredictable(f"{what} animates {fc.data_path}")
            if fc.data_path in _OBJECT_CHANNELS:
                self.curves.append((fc.data_path, fc.array_index, fc))

    def matrix(self, time):
        """The world matrix (4x4 float64) at scene time `time`."""
        from mathutils import Euler, Matrix, Quaternion, Vector

        obj = self.obj
        if not self.curves:
            return _matrix(obj.matrix_basis)
        if (
            tuple(obj.delta_rotation_euler) != (0.0, 0.0, 0.0)
            or tuple(obj.delta_rotation_quaternion) != (1.0, 0.0, 0.0, 0.0)
            or tuple(obj.delta_scale) != (1.0, 1.0, 1.0)
        ):
            raise Unpredictable("the object has delta rotation or scale")
        values = {
            "location": list(obj.location),
            "scale": list(obj.scale),
            "rotation_euler": list(obj.rotation_euler),
            "rotation_quaternion": list(obj.rotation_quaternion),
            "rotation_axis_angle": list(obj.rotation_axis_angle),
        }
        for path, index, fc in self.curves:
            values[path][index] = fc.evaluate(time)
        mode = obj.rotation_mode
        if mode == "QUATERNION":
            rotation = Quaternion(values["rotation_quaternion"]).normalized().to_matrix()
        elif mode == "AXIS_ANGLE":
            angle, *axis = values["rotation_axis_angle"]
            rotation = Quaternion(Vector(axis).normalized(), angle).to_matrix()
        else:
            rotation = Euler(values["rotation_euler"], mode).to_matrix()
        location = Vector(values["location"]) + obj.delta_location
        return _matrix(Matrix.LocRotScale(location, rotation, Vector(values["scale"])))

    def position(self, time):
        """The world position at `time` (only the location channels matter)."""
        obj = self.obj
        location = list(obj.location)
        for path, index, fc in self.curves:
            if path == "location":
                location[index] = fc.evaluate(time)
        return np.array(location, np.float64) + np.array(obj.delta_location, np.float64)


class PosePredictor:
    """The armature-space matrices of `input_bones` (indices into obj.pose.bones) and the
    armature's world matrix at a frame, from the rig's action alone. Raises Unpredictable
    when built on a rig whose inputs depend on anything else."""

    def __init__(self, obj, input_bones, written_bones):
        pose_bones = obj.pose.bones
        if obj.data.animation_data is not None and (
            len(obj.data.animation_data.drivers) or obj.data.animation_data.action is not None
        ):
            raise Unpredictable("the armature data is animated")
        self.motion = ObjectMotion(obj, "the armature")
        names = pose_bones.keys()  # one call into Blender, not one per bone
        index = {name: i for i, name in enumerate(names)}
        # The input bones and their ancestors, parents first.
        needed = set()
        for i in input_bones:
            bone = pose_bones[i]
            while bone is not None and index[bone.name] not in needed:
                needed.add(index[bone.name])
                bone = bone.parent
        _refuse_constraints(pose_bones, names, index, needed)
        written = {names[i] for i in written_bones}
        _refuse_drivers(obj, "the armature", {names[i] for i in needed} | written)
        order = sorted(needed, key=lambda i: (_depth(pose_bones[i]), i))
        position = {b: k for k, b in enumerate(order)}
        self.bones = [pose_bones[i] for i in order]
        self.rows = np.array([position[i] for i in input_bones], np.int64)
        self.input_bones = np.array(input_bones, np.int64)
        self.parents = np.array(
            [position[index[pb.parent.name]] if pb.parent else -1 for pb in self.bones], np.int32
        )
        self.rest = np.array(
            [_matrix(pb.bone.matrix_local).reshape(-1) for pb in self.bones]
        ).reshape(-1, 16)
        modes, inherit_rotation, inherit_scale = [], [], []
        for pb in self.bones:
            scale_mode = pb.bone.inherit_scale
            # NONE and AVERAGE under an inherited rotation take the parent's orientation without
            # its shear: measured off by up to 0.03 against Blender's evaluation under a sheared
            # parent (with a hinge they match), so such rigs are left to the evaluated path.
            if scale_mode not in INHERIT_SCALE or (
                scale_mode in ("NONE", "AVERAGE") and pb.bone.use_inherit_rotation and pb.parent
            ):
                raise Unpredictable(f"bone '{pb.name}' inherits scale {scale_mode}")
            if pb.parent is not None and not pb.bone.use_local_location:
                raise Unpredictable(f"bone '{pb.name}' moves in the armature's space")
            modes.append(ROTATION_MODES[pb.rotation_mode])
            inherit_rotation.append(1 if pb.bone.use_inherit_rotation else 0)
            inherit_scale.append(INHERIT_SCALE[pb.bone.inherit_scale])
        self.modes = np.array(modes, np.int32)
        self.inherit_rotation = np.array(inherit_rotation, np.int32)
        self.inherit_scale = np.array(inherit_scale, np.int32)
        self.rotation_properties = [_rotation_property(pb.rotation_mode) for pb in self.bones]
        # F-curves of the bones in the chain (bone row, first column, fcurve), and refusals.
        self.curves = []
        for fc in _evaluated_curves(obj, "the armature"):
            match = _BONE_PATH.match(fc.data_path)
            if match is None:
                continue
            name, prop = _unescape(match.group(1)), match.group(2)
            if name in written and prop == "rotation_quaternion":
                raise Unpredictable(f"the action keys the rod bone '{name}'")
            if name not in index or index[name] not in position:
                continue
            row = position[index[name]]
            if prop == "rotation_mode":
                raise Unpredictable(f"the action keys the rotation mode of '{name}'")
            if prop in _BONE_CHANNELS and (
                prop in ("location", "scale") or prop == self.rotation_properties[row]
            ):
                self.curves.append((row, _BONE_CHANNELS[prop][0] + fc.array_index, fc))
        self.channels = np.zeros((len(self.bones), 10), np.float64)
        self._cameras = {}

    def camera_position(self, camera, time):
        """The camera's world position at `time`, or None when its motion cannot be predicted."""
        key = camera.as_pointer()
        if key not in self._cameras:
            try:
                self._cameras[key] = ObjectMotion(camera, "the camera", position_only=True)
            except Unpredictable:
                self._cameras[key] = None
        motion = self._cameras[key]
        return None if motion is None else motion.position(time)

    def predict(self, time):
        """(input bone matrices (N, 16) float32 in foreach_get's column-major order, the
        armature's world matrix) at scene time `time`."""
        channels = self.channels
        # Few bones (the rods' inputs and their ancestors): their current channels, then
        # Blender's own F-curve evaluation of the animated ones.
        for row, pb in enumerate(self.bones):
            channels[row, 0:3] = pb.location
            rotation = getattr(pb, self.rotation_properties[row])
            channels[row, 3 : 3 + len(rotation)] = rotation
            channels[row, 7:10] = pb.scale
        for row, column, fc in self.curves:
            channels[row, column] = fc.evaluate(time)
        pose = native.module().pose_forward_kinematics(
            parents=self.parents,
            rest=self.rest,
            channels=channels,
            rotation_modes=self.modes,
            inherit_rotation=self.inherit_rotation,
            inherit_scale=self.inherit_scale,
        )
        matrices = pose[self.rows].reshape(-1, 4, 4).transpose(0, 2, 1).reshape(-1, 16)
        return matrices.astype(np.float32), self.motion.matrix(time)


def _refuse_constraints(pose_bones, names, index, needed):
    """Raises when a constraint can move one of the `needed` bones (the rods' inputs and their
    ancestors): a constraint on one of them, or an IK or Spline IK chain reaching one of them
    from a bone below (chain length 0: to the root). Constraints elsewhere (an IK leg, a
    constrained prop) move only their own bones and those below. `names`: pose_bones.keys(),
    in the same order (every bone is looked at once a playback: at 16,000 bones this walk is
    most of PosePredictor's set-up, so a bone's name is asked for only when it has
    constraints)."""
    for i, constraints in enumerate(map(_CONSTRAINTS, pose_bones)):
        if not len(constraints):
            continue
        pb = pose_bones[names[i]]
        if i in needed:
            raise Unpredictable(f"bone '{pb.name}' has constraints")
        for con in constraints:
            if con.type not in ("IK", "SPLINE_IK"):
                continue
            # chain_count bones from the owner up (0: to the root); the owner is not needed.
            length = con.chain_count or len(pose_bones)
            bone = pb.parent
            for _ in range(length - 1):
                if bone is None:
                    break
                if index[bone.name] in needed:
                    raise Unpredictable(
                        f"the {con.type} chain of '{pb.name}' reaches '{bone.name}'"
                    )
                bone = bone.parent


def _matrix(matrix):
    """A mathutils 4x4 matrix as a C-contiguous float64 array, row-major."""
    return np.array([tuple(row) for row in matrix], np.float64)


def _depth(pose_bone):
    depth = 0
    while pose_bone.parent is not None:
        depth, pose_bone = depth + 1, pose_bone.parent
    return depth


def close(predicted, actual):
    """True when every value of `predicted` is within TOLERANCE of `actual` (relative above 1)."""
    predicted = np.asarray(predicted, np.float64)
    actual = np.asarray(actual, np.float64)
    return bool(np.all(np.abs(predicted - actual) <= TOLERANCE * np.maximum(1.0, np.abs(actual))))


class Prediction:
    """A frame solved before the pass from predicted inputs, until evaluate() checks it."""

    def __init__(self, frame, previous, matrices, armature, camera, gravity, rotations, view):
        """view: whether a rod has view keys (else the camera's position changes nothing)."""
        self.frame, self.previous, self.view = frame, previous, view
        self.matrices, self.armature, self.camera, self.gravity = (
            matrices,
            armature,
            camera,
            gravity,
        )
        self.rotations = rotations.copy()

    def mismatch(self, matrices, armature, camera, gravity):
        """None when Blender's inputs are the predicted ones, else what differed."""
        if not close(self.matrices, matrices):
            return "a bone the rods read was not where its action put it"
        if not close(self.armature, armature):
            return "the armature was not where its action put it"
        if (camera is None) != (self.camera is None) or (
            self.view and camera is not None and not close(self.camera, camera)
        ):
            return "the camera was not where its action put it"
        if not close(self.gravity, gravity):
            return "the scene's gravity changed"
        return None
