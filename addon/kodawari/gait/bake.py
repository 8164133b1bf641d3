"""The gait bake as a job: validate and solve first (nothing touched), then write the
Action in steps a modal operator can interleave with progress and Esc, or run at once.
Cancel puts back exactly what was there."""

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import fcurves, native
from ..bake_job import BakeJob
from . import rig as rigmod
from . import runtime
from .props import GAIT_NAMES, LEG_NAMES

CONTACT_PROPS = tuple(f"kodawari_contact_{leg}" for leg in LEG_NAMES)
GAIT_PROP = (
    "kodawari_gait_index"  # the gait in use per frame (0 WALK .. 4 GALLOP_ROTARY), for the report
)


def _sample_channel(obj, data_path, frames, constant):
    """Per-frame values of an animated setting (one evaluate per frame), else constant."""
    anim = obj.animation_data
    curve = None
    if anim is not None and anim.action is not None:
        curve = fcurves.find_fcurve(anim.action, obj, data_path)
    if curve is None:
        return np.full(len(frames), constant, dtype=np.float64)
    return np.array([curve.evaluate(float(f)) for f in frames], dtype=np.float64)


def _path_points(context, obj, path_obj):
    depsgraph = context.evaluated_depsgraph_get()
    evaluated = path_obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        n = len(mesh.vertices)
        co = np.empty(n * 3, dtype=np.float64)
        mesh.vertices.foreach_get("co", co)
    finally:
        evaluated.to_mesh_clear()
    if n < 2:
        raise ValueError(tip_("the path curve '{}' has no length").format(path_obj.name))
    # World points less the armature's placement: the gait frame (rig.gait_frame).
    m = path_obj.matrix_world
    rotation = rigmod.mat3(m)
    offset = np.array([float(m[i][3]) for i in range(3)]) - rigmod.gait_origin(obj)
    pts = co.reshape(-1, 3) @ rotation.T + offset
    return np.ascontiguousarray(pts)


def _run_region(rig, speed, fps, path, margin):
    """(lo, hi) in the gait frame's x, y: where the animal can go, from the keyed speeds
    (the acceleration limit only shortens the run) along its heading or path."""
    head = rig["body_head"][:2]
    distance = float(np.sum(speed) / fps) + 1.0
    if path is not None:
        points = np.vstack([path[:, :2], head[None, :]])
        d = path[-1, :2] - path[-2, :2]
        points = np.vstack([points, path[-1, :2] + d / max(np.linalg.norm(d), 1e-9) * distance])
    else:
        points = np.array([head, head + rig["forward"][:2] * distance])
    feet = np.array([leg["tail"][:2] for leg in rig["legs"]])
    reach = float(np.max(np.linalg.norm(feet - head, axis=1))) + margin
    return points.min(axis=0) - reach, points.max(axis=0) + reach


def _heightfield(context, obj, ground, rig, lo, hi, max_cells=256):
    """Ground heights (gait frame) on a grid over the run, by ray casts straight down
    onto the ground mesh. Raises ValueError when rays miss."""
    from mathutils import Vector
    from mathutils.bvhtree import BVHTree

    depsgraph = context.evaluated_depsgraph_get()
    tree = BVHTree.FromObject(ground.evaluated_get(depsgraph), depsgraph)
    cell = max(float((hi - lo).max()) / (max_cells - 1), 0.05)
    nx = int(np.ceil((hi[0] - lo[0]) / cell)) + 1
    ny = int(np.ceil((hi[1] - lo[1]) / cell)) + 1
    origin = Vector(rigmod.gait_origin(obj))
    to_ground = ground.matrix_world.inverted()
    top = float(max(leg["heads"][0][2] for leg in rig["legs"])) + 1000.0
    direction = (to_ground.to_3x3() @ Vector((0.0, 0.0, -1.0))).normalized()
    heights = np.empty(nx * ny, dtype=np.float64)
    misses = 0
    # One ray per grid cell (not per frame): a set-up cost, like reading the rig.
    for j in range(ny):
        y = lo[1] + j * cell
        for i in range(nx):
            hit = tree.ray_cast(
                to_ground @ (origin + Vector((lo[0] + i * cell, y, top))), direction
            )
            if hit[0] is None:
                heights[j * nx + i] = np.nan
                misses += 1
            else:
                heights[j * nx + i] = (ground.matrix_world @ hit[0]).z - origin.z
    if misses:
        raise ValueError(
            tip_(
                "the ground '{}' does not lie under the whole run ({} of {} rays missed): move or enlarge it, or clear Ground"
            ).format(ground.name, misses, nx * ny)
        )
    return {
        "x0": float(lo[0]),
        "y0": float(lo[1]),
        "cell": cell,
        "nx": nx,
        "ny": ny,
        "heights": heights,
    }


def object_motion(rig, result):
    """Root motion on the object: (delta location (F, 3), delta rotation quaternions
    (F, 4) w-first) from the body motion the core solved about the leg roots' centre
    (body_rest is the identity there). Blender composes the delta rotation before the
    object's own (world = T(loc + dloc) R_delta R_own S), so the delta location is the
    pivot's travel less the rotated pivot."""
    q = result["body_rotation"] / np.linalg.norm(result["body_rotation"], axis=1, keepdims=True)
    w, x, y, z = q.T
    rot = np.stack(
        [
            np.stack([1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)], axis=1),
            np.stack([2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)], axis=1),
            np.stack([2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)], axis=1),
        ],
        axis=1,
    )
    pivot = rig["body_head"]
    head = pivot[None, :] + result["body_location"]
    return head - rot @ pivot, q


def euler_xyz(q):
    """Quaternions (F, 4) w-first to XYZ Euler angles (F, 3), unwrapped over time."""
    w, x, y, z = q.T
    ex = np.arctan2(2 * (w * x + y * z), 1 - 2 * (x * x + y * y))
    ey = np.arcsin(np.clip(2 * (w * y - z * x), -1.0, 1.0))
    ez = np.arctan2(2 * (w * z + x * y), 1 - 2 * (y * y + z * z))
    return np.unwrap(np.stack([ex, ey, ez], axis=1), axis=0)


class GaitBakeJob(BakeJob):
    """validate+solve in __init__ (raises ValueError), then begin/steps/finish or cancel;
    prepare/step are the BakeJob protocol (bake_job.py) over begin/steps."""

    title = "Gait bake"

    def __init__(self, context, obj, frame_start, frame_end):
        if obj is None or obj.type != "ARMATURE":
            raise ValueError(tip_("the active object is not an armature"))
        if frame_end <= frame_start:
            raise ValueError(tip_("frame_end must be after frame_start"))
        kn = native.module()
        settings = obj.kodawari_gait
        self.obj = obj
        self.scene = context.scene
        self.frames = np.arange(frame_start, frame_end + 1, dtype=np.float64)
        self.fps = self.scene.render.fps / self.scene.render.fps_base
        self.rig, self.chains = rigmod.rig_dict(obj, settings)
        if self.rig["on_object"] and obj.rotation_mode not in ("XYZ", "QUATERNION"):
            raise ValueError(
                tip_(
                    "root motion on the object keys its delta rotation: set '{}' to the XYZ Euler or Quaternion rotation mode (it is {})"
                ).format(obj.name, obj.rotation_mode)
            )
        self.table = rigmod.table_dict(settings)
        why = kn.gait_validate_table(self.table)
        if why:
            raise ValueError(why)
        speed = _sample_channel(obj, "kodawari_gait.speed", self.frames, settings.speed)
        gait_index = GAIT_NAMES.index(settings.gait) if settings.gait != "AUTO" else -1
        mode = _sample_channel(obj, "kodawari_gait.gait", self.frames, gait_index + 1) - 1
        mode = np.clip(np.round(mode), -1, 4)
        if (speed < 0).any():
            f = int(self.frames[np.argmax(speed < 0)])
            raise ValueError(
                tip_("speed is negative ({:.2f} m/s at frame {}): key speeds of 0 or more").format(
                    speed[speed < 0][0], f
                )
            )
        length = rigmod.leg_length(self.rig)
        frame, top = kn.gait_check_speeds(
            self.table,
            np.ascontiguousarray(speed),
            np.ascontiguousarray(mode, dtype=np.float64),
            length,
        )
        if frame >= 0:
            g = int(mode[frame])
            what = "the gait table" if g < 0 else GAIT_NAMES[g]
            raise ValueError(
                tip_(
                    "speed {:.2f} m/s at frame {} is past the range of {} (top {:.2f} m/s): lower it or raise the table's top speed"
                ).format(speed[frame], int(self.frames[frame]), what, top)
            )
        path = _path_points(context, obj, settings.path) if settings.path is not None else None
        ground = None
        if settings.ground is not None:
            lo, hi = _run_region(self.rig, speed, self.fps, path, margin=1.0)
            ground = _heightfield(context, obj, settings.ground, self.rig, lo, hi)
        result = kn.gait_bake(
            self.rig,
            self.table,
            np.ascontiguousarray(speed),
            np.ascontiguousarray(mode, dtype=np.float64),
            float(self.fps),
            float(settings.acceleration),
            int(settings.ccd_iterations),
            path=path,
            ground=ground,
        )
        if ground is not None:
            planted = result["contacts"] > 0.5
            miss = np.where(planted, result["ik_error"], 0.0)
            if miss.max() > 0.02:
                f = int(self.frames[np.argmax(miss.max(axis=1))])
                raise ValueError(
                    tip_(
                        "the ground '{}' is out of the legs' reach (a planted foot misses it by {:.2f} m at frame {})"
                    ).format(settings.ground.name, miss.max(), f)
                )
        self.result = result
        self.axes = rigmod.hinge_axes(obj, self.chains, self.rig["forward"])
        self._started = False

    # --- writing -------------------------------------------------------------------
    def begin(self):
        obj = self.obj
        anim = obj.animation_data
        self._old_action = anim.action if anim is not None else None
        self._old_slot = fcurves.current_slot_identifier(obj)
        self._old_modes = {pb.name: pb.rotation_mode for pb in obj.pose.bones}
        self._old_deltas = (
            tuple(obj.delta_location),
            tuple(obj.delta_rotation_euler),
            tuple(obj.delta_rotation_quaternion),
        )
        self._old_props = {k: obj[k] for k in CONTACT_PROPS + (GAIT_PROP,) if k in obj.keys()}
        # A new Action (the old one stays untouched until finish, so Esc can put it
        # back); the curves this bake does not own (the speed keys, other bones) are
        # copied over, the gait channels are written fresh.
        owned = self._owned_paths()
        kept = []
        if self._old_action is not None:
            kept = [
                fcurves.copy_keys(c)
                for c in fcurves.action_fcurves(self._old_action, obj)
                if c.data_path not in owned
            ]
        action = bpy.data.actions.new(
            self._old_action.name if self._old_action else f"{obj.name}Gait"
        )
        self.action = action
        fcurves.assign_action(obj, action, None)
        for data in kept:
            fcurves.copy_into(action, obj, data)
        self._started = True

    def _owned_paths(self):
        bones = [n for leg in LEG_NAMES for n in self.chains[leg]]
        paths = {f'pose.bones["{n}"].rotation_quaternion' for n in bones}
        paths.update(f'pose.bones["{n}"].rotation_euler' for n in bones)
        if self.rig["on_object"]:
            paths.update(("delta_location", "delta_rotation_euler", "delta_rotation_quaternion"))
        else:
            body = self.obj.kodawari_gait.body_bone
            paths.update(
                (f'pose.bones["{body}"].location', f'pose.bones["{body}"].rotation_quaternion')
            )
        paths.update(f'["{p}"]' for p in CONTACT_PROPS + (GAIT_PROP,))
        return paths

    def steps(self):
        """Write one channel group per step; yields the fraction done."""
        obj, action, frames, r = self.obj, self.action, self.frames, self.result
        settings = obj.kodawari_gait
        jobs = []
        column = 0
        for leg in LEG_NAMES:
            for name in self.chains[leg]:
                jobs.append(("bone", name, column))
                column += 1
        jobs += [("body", settings.body_bone, None), ("contacts", None, None)]
        for i, (kind, name, col) in enumerate(jobs):
            if kind == "bone":
                axis = self.axes[name]
                mode, sign = rigmod.hinge_channel(axis)
                if mode == "X":
                    # A hinge about the bone's own X axis: one Euler channel says it all.
                    obj.pose.bones[name].rotation_mode = "XYZ"
                    euler = np.zeros((len(frames), 3))
                    euler[:, 0] = sign * r["angles"][:, col]
                    fcurves.write_channels(
                        action,
                        obj,
                        f'pose.bones["{name}"].rotation_euler',
                        frames,
                        euler[:, :1],
                        group=name,
                    )
                else:
                    obj.pose.bones[name].rotation_mode = "QUATERNION"
                    half = r["angles"][:, col] / 2
                    quat = np.stack(
                        [
                            np.cos(half),
                            axis[0] * np.sin(half),
                            axis[1] * np.sin(half),
                            axis[2] * np.sin(half),
                        ],
                        axis=1,
                    )
                    fcurves.write_channels(
                        action,
                        obj,
                        f'pose.bones["{name}"].rotation_quaternion',
                        frames,
                        quat,
                        group=name,
                    )
            elif kind == "body" and self.rig["on_object"]:
                # Root motion on the object, in its delta transforms (its own location,
                # rotation and scale stay the user's placement).
                location, quat = object_motion(self.rig, r)
                fcurves.write_channels(
                    action, obj, "delta_location", frames, location, group="Object Transforms"
                )
                if obj.rotation_mode == "QUATERNION":
                    fcurves.write_channels(
                        action,
                        obj,
                        "delta_rotation_quaternion",
                        frames,
                        quat,
                        group="Object Transforms",
                    )
                else:
                    fcurves.write_channels(
                        action,
                        obj,
                        "delta_rotation_euler",
                        frames,
                        euler_xyz(quat),
                        group="Object Transforms",
                    )
            elif kind == "body":
                obj.pose.bones[name].rotation_mode = "QUATERNION"
                # The core solved in world metres: a bone's location is in armature units.
                fcurves.write_channels(
                    action,
                    obj,
                    f'pose.bones["{name}"].location',
                    frames,
                    r["body_location"] / self.rig["scale"],
                    group=name,
                )
                fcurves.write_channels(
                    action,
                    obj,
                    f'pose.bones["{name}"].rotation_quaternion',
                    frames,
                    r["body_rotation"],
                    group=name,
                )
            else:
                for k, prop in enumerate(CONTACT_PROPS):
                    obj[prop] = float(r["contacts"][0, k])
                    fcurves.write_channels(
                        action,
                        obj,
                        f'["{prop}"]',
                        frames,
                        r["contacts"][:, k],
                        group="Kodawari Gait",
                        interpolation="CONSTANT",
                    )
                obj[GAIT_PROP] = float(r["gait"][0])
                fcurves.write_channels(
                    action,
                    obj,
                    f'["{GAIT_PROP}"]',
                    frames,
                    r["gait"].astype(np.float64),
                    group="Kodawari Gait",
                    interpolation="CONSTANT",
                )
            yield (i + 1) / len(jobs)

    def finish(self):
        old = self._old_action
        if old is not None and old.users == 0 and not old.use_fake_user:
            name = old.name
            bpy.data.actions.remove(old)
            self.action.name = name
        runtime.remember(self.obj, self)
        self.obj.update_tag()
        return tip_("Baked {} frames of gait on '{}'").format(len(self.frames), self.obj.name)

    def cancel(self):
        """Put back the action, slot, rotation modes and custom properties."""
        if not self._started:
            return
        obj = self.obj
        fcurves.assign_action(obj, self._old_action, self._old_slot)
        if self._old_action is None and obj.animation_data is not None:
            obj.animation_data.action = None
        bpy.data.actions.remove(self.action)
        for name, mode in self._old_modes.items():
            if name in obj.pose.bones:
                obj.pose.bones[name].rotation_mode = mode
        obj.delta_location, obj.delta_rotation_euler, obj.delta_rotation_quaternion = (
            self._old_deltas
        )
        for key in CONTACT_PROPS + (GAIT_PROP,):
            if key in self._old_props:
                obj[key] = self._old_props[key]
            elif key in obj.keys():
                del obj[key]
        self._started = False

    # --- the BakeJob protocol ---------------------------------------------------------
    def prepare(self):
        self.begin()
        self._pending = self.steps()

    def step(self):
        return next(self._pending, 1.0)

    def run(self):
        self.begin()
        for _ in self.steps():
            pass
        self.finish()
