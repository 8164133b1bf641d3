"""Reading a quadruped rig: finding its legs and body bone, its rest data for the
native planner, and the horse defaults. Set-up time only; no per-frame work here."""

import math

import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import native
from . import legs as legfinder
from .props import GAIT_NAMES, LEG_NAMES

# Kept here for callers of the set-up API.
find_legs_by_name = legfinder.find_legs_by_name
find_legs_from_feet = legfinder.find_legs_from_feet
find_body = legfinder.find_body
with_shoulders = legfinder.with_shoulders

# The seed's joint ranges (4.x, degrees, each bone relative to its parent, the first
# relative to straight down, positive swinging the tip backward), widened where the
# seed's gallop snapshot cannot reach its own +-0.8 m (scapula +-3 deg, humerus +-1 deg).
# The HORSE preset, for 4-bone legs; every other leg gets ranges from its rest pose.
HORSE_FORE_LIMITS = ((-55.0, -15.0), (60.0, 100.0), (-135.0, -5.0), (0.0, 120.0))
HORSE_HIND_LIMITS = ((40.0, 75.0), (-125.0, -55.0), (10.0, 125.0), (-135.0, 0.0))
HORSE_STIFFNESS = (0.1, 0.3, 0.5, 1.0)
LIMIT_PRESETS = ("REST", "HORSE")


def mat3(matrix):
    """A mathutils 3x3 (or the 3x3 of a 4x4) as a C-ordered float64 array, row by row
    (np.array(Matrix) changed memory order between Blender versions)."""
    return np.array([[float(matrix[i][j]) for j in range(3)] for i in range(3)], dtype=np.float64)


def mat4(matrix):
    """A mathutils 4x4 as a C-ordered float64 array, row by row."""
    return np.array([[float(matrix[i][j]) for j in range(4)] for i in range(4)], dtype=np.float64)


def placement(obj):
    """The armature's world matrix as the gait reads it (4x4 mathutils). With root
    motion on the object the bake keys its delta transforms, so its placement is its
    own location, rotation and scale without them."""
    from mathutils import Matrix, Quaternion

    if obj.kodawari_gait.root_motion != "OBJECT" or obj.parent is not None:
        return obj.matrix_world.copy()
    mode = obj.rotation_mode
    if mode == "QUATERNION":
        rotation = obj.rotation_quaternion
    elif mode == "AXIS_ANGLE":
        a = obj.rotation_axis_angle
        rotation = Quaternion((a[1], a[2], a[3]), a[0])
    else:
        rotation = obj.rotation_euler
    return Matrix.LocRotScale(obj.location, rotation, obj.scale)


def gait_frame(obj):
    """(M, s): the armature's world rotation times its scale (3x3) and that scale. The
    gait core works in this frame (docs/algorithms.md §4.11): world metres and world up, armature-space points
    p mapped to M p (the placement's translation left out). Raises ValueError for a
    non-uniform or mirroring scale, which no hinge survives."""
    m = mat3(placement(obj))
    scales = np.linalg.norm(m, axis=0)
    if not np.all(scales > 1e-9) or scales.max() - scales.min() > 1e-4 * scales.max():
        raise ValueError(
            tip_(
                "'{}' has a non-uniform scale ({}): apply the scale (Ctrl+A > Scale) first"
            ).format(obj.name, ", ".join(f"{v:.3g}" for v in scales))
        )
    if np.linalg.det(m) < 0:
        raise ValueError(
            tip_("'{}' has a negative (mirroring) scale: apply the scale first").format(obj.name)
        )
    return m, float(scales.mean())


def gait_origin(obj):
    """World position of the gait frame's origin (the placement's translation)."""
    t = placement(obj).translation
    return np.array([float(t[0]), float(t[1]), float(t[2])])


def frame_up(obj):
    """World up in armature space (unit)."""
    m, s = gait_frame(obj)
    up = (m / s).T @ np.array([0.0, 0.0, 1.0])
    return up / np.linalg.norm(up)


def _points(obj, names, attr):
    """Rest points of bones (armature space) mapped into the gait frame."""
    m, _ = gait_frame(obj)
    bones = obj.data.bones
    return np.array([getattr(bones[n], attr) for n in names], dtype=np.float64).reshape(-1, 3) @ m.T


def leg_points(obj, names):
    """(heads (n, 3), tail (3,)) of a leg in the gait frame."""
    return _points(obj, names, "head_local"), _points(obj, names[-1:], "tail_local")[0]


def seed_angles(obj, names, forward):
    """Each bone's rest angle relative to its parent (the first: to straight down),
    degrees, positive swinging the tip backward (the seed's convention), in the gait
    frame."""
    heads, tail = leg_points(obj, names)
    points = np.vstack([heads, tail[None, :]])
    previous = 0.0
    out = []
    for d in np.diff(points, axis=0):
        absolute = math.degrees(math.atan2(-float(d @ forward), -float(d[2])))
        out.append(absolute - previous)
        previous = absolute
    return out


def forward_of(obj, legs):
    """The horizontal direction the animal faces in the gait frame: hind roots to fore roots."""
    roots = {k: _points(obj, legs[k][:1], "head_local")[0] for k in LEG_NAMES}
    f = (roots["LF"] + roots["RF"] - roots["LH"] - roots["RH"]) / 2
    f[2] = 0.0
    n = np.linalg.norm(f)
    return f / n if n > 1e-9 else np.array([0.0, -1.0, 0.0])


def rest_limits(rest, lengths):
    """Pose-relative hinge ranges (degrees) from a leg's rest pose (docs/algorithms.md
    §4.9). `rest`: each bone's rest angle relative to its
    parent (the first: to straight down); `lengths`: bone lengths in the leg's plane.

    The first bone swings +-45 deg about its rest (+-25 when it is a girdle bone above a
    leg of 6). Every other joint bends the way it bends at rest (a joint nearly
    straight at rest bends opposite to the joint above it: legs zig-zag), may straighten
    to 5 deg past straight, never further (no knee reverses), and may bend 90 deg more
    than at rest (40 deg for a bone shorter than a fifth of the leg: toes and hooves do
    not curl back to the knee)."""
    n = len(rest)
    total = float(sum(lengths))
    first = 25.0 if n >= 6 else 45.0
    lo, hi = [-first], [first]
    previous = None
    for k in range(1, n):
        r = rest[k]
        if abs(r) >= 10.0:
            d = 1.0 if r > 0 else -1.0
        elif previous is not None:
            d = -previous
        else:
            d = -1.0 if rest[0] > 0 else 1.0
        flex = d * r  # how far the joint is bent at rest, in its bending direction
        span = 90.0 if lengths[k] >= 0.2 * total else 40.0
        f_lo, f_hi = min(flex, 0.0) - 5.0, max(min(flex + span, 160.0), flex)
        if d > 0:
            lo.append(f_lo - r)
            hi.append(f_hi - r)
        else:
            lo.append(-f_hi - r)
            hi.append(-f_lo - r)
        previous = d
    return lo, hi


def leg_stiffness(n, fore, rest, lengths=None):
    """CCD stiffness ratios from hip to foot (seed 3.2): the fore leg's (0.1, 0.3, 0.5,
    1.0) spread over its bones; in the hind leg the femur leads (the largest share), the
    bones below follow the fore pattern. The femur is the first bone, or the second when
    the first is a pelvis sloping more than 45 deg (the sample horse). Digits (bones
    shorter than a fifth of the leg) take at most 0.3: toes and hooves follow the leg."""
    out = _leg_stiffness(n, fore, rest)
    if lengths is not None:
        total = float(np.sum(lengths))
        out = [min(v, 0.3) if lengths[k] < 0.2 * total and k > 0 else v for k, v in enumerate(out)]
    return out


def _leg_stiffness(n, fore, rest):
    base = (
        np.interp(np.linspace(0, 1, n), np.linspace(0, 1, 4), HORSE_STIFFNESS)
        if n > 1
        else np.ones(1)
    )
    if fore or n < 2:
        return [float(v) for v in base]
    femur = 1 if n >= 4 and abs(rest[0]) > 45.0 else 0
    out = [float(v) for v in base]
    out[femur] = 1.0
    below = (
        np.interp(np.linspace(0, 1, n - femur - 1), np.linspace(0, 1, 3), (0.3, 0.5, 0.7))
        if n - femur > 1
        else []
    )
    for i, v in enumerate(below):
        out[femur + 1 + i] = float(v)
    for i in range(femur):
        out[i] = 0.1
    return out


def fill_defaults(settings, obj, legs, body, preset="REST", root_motion=None):
    """The gait settings for a rig: the horse table scaled to the rig's leg length
    (Froude), joint ranges from each leg's rest pose (or the HORSE preset for 4-bone
    legs), fore and hind stiffness, the body bone and where root motion goes."""
    kn = native.module()
    forward = forward_of(obj, legs)
    hind = [leg_points(obj, legs[k]) for k in ("LH", "RH")]
    length = max(float(h[0][0][2] - h[1][2]) for h in hind)
    table = kn.gait_horse_table(length)
    settings.table.clear()
    for name, row in zip(GAIT_NAMES, table["gaits"]):
        entry = settings.table.add()
        entry.name = name
        for column, value in zip(kn.GAIT_COLUMNS, row):
            setattr(entry, column, bool(value) if column == "use_in_auto" else float(value))
    settings.use_froude = bool(table["use_froude"])
    settings.hysteresis = float(table["hysteresis"])
    settings.reach = float(table["reach"])
    settings.body_bone = body or ""
    settings.root_motion = root_motion or ("BONE" if body else "OBJECT")
    settings.legs.clear()
    for leg in LEG_NAMES:
        item = settings.legs.add()
        item.name = leg
        names = legs[leg]
        rest = seed_angles(obj, names, forward)
        heads, tail = leg_points(obj, names)
        d = np.diff(np.vstack([heads, tail[None, :]]), axis=0)
        lengths = np.hypot(d @ forward, d[:, 2])
        fore = leg.endswith("F")
        if preset == "HORSE" and len(names) == 4:
            ranges = HORSE_FORE_LIMITS if fore else HORSE_HIND_LIMITS
            lo = [a - r for (a, _), r in zip(ranges, rest)]  # pose angles from the rest pose
            hi = [b - r for (_, b), r in zip(ranges, rest)]
            stiffness = HORSE_STIFFNESS
        else:
            lo, hi = rest_limits(rest, lengths)
            stiffness = leg_stiffness(len(names), fore, rest, lengths)
        for k, name in enumerate(names):
            bone = item.bones.add()
            bone.name = name
            bone.limit_min, bone.limit_max = float(lo[k]), float(hi[k])
            bone.stiffness = float(stiffness[k])


def fill_horse_defaults(settings, obj, legs, body):
    """The HORSE preset (the seed's joint ranges for 4-bone legs)."""
    fill_defaults(settings, obj, legs, body, preset="HORSE")


def table_dict(settings):
    kn = native.module()
    rows = []
    by_name = {e.name: e for e in settings.table}
    for name in GAIT_NAMES:
        entry = by_name.get(name)
        if entry is None:
            raise ValueError(tip_("the gait table has no {} row: run Gait Setup").format(name))
        rows.append([float(getattr(entry, c)) for c in kn.GAIT_COLUMNS])
    return {
        "gaits": np.array(rows, dtype=np.float64),
        "use_froude": bool(settings.use_froude),
        "hysteresis": float(settings.hysteresis),
        "reach": float(settings.reach),
    }


def rig_dict(obj, settings):
    """The rig as the native planner reads it: the gait frame (world metres, world up;
    see gait_frame), radians. Root motion on the OBJECT pivots about the leg roots'
    centre. Raises ValueError with a sentence for the user when something is missing."""
    armature = obj.data
    legs = {}
    for leg in settings.legs:
        names = [b.name for b in leg.bones]
        if len(names) < 2:
            raise ValueError(
                tip_("leg {} has {} bone(s); a leg needs 2 to 6").format(leg.name, len(names))
            )
        if len(names) > 6:
            raise ValueError(
                tip_("leg {} has {} bones; a leg needs 2 to 6").format(leg.name, len(names))
            )
        for n in names:
            if n not in armature.bones:
                raise ValueError(
                    tip_("leg {}: bone '{}' is not in the armature").format(leg.name, n)
                )
        legs[leg.name] = leg
    missing = [k for k in LEG_NAMES if k not in legs]
    if missing:
        raise ValueError(
            tip_("fewer than four legs set up (missing {}): run Gait Setup").format(
                ", ".join(missing)
            )
        )
    on_object = settings.root_motion == "OBJECT"
    if not on_object and settings.body_bone not in armature.bones:
        raise ValueError(
            tip_(
                "no body bone set (the bone carrying root motion): run Gait Setup, or set Root Motion to Armature Object"
            )
        )
    if not on_object and armature.bones[settings.body_bone].use_connect:
        raise ValueError(
            tip_(
                "the body bone '{}' is connected to its parent, so Blender ignores its location keys: choose an unconnected bone or Root Motion: Armature Object"
            ).format(settings.body_bone)
        )
    if on_object and obj.parent is not None:
        raise ValueError(
            tip_(
                "'{}' has a parent: root motion on the object needs an unparented armature (or use Root Motion: Body Bone)"
            ).format(obj.name)
        )
    m, scale = gait_frame(obj)
    chains = {k: [b.name for b in legs[k].bones] for k in LEG_NAMES}
    forward = forward_of(obj, chains)
    if on_object:
        roots = np.array([leg_points(obj, chains[k])[0][0] for k in LEG_NAMES])
        head, rest = roots.mean(axis=0), np.eye(3)
    else:
        body = armature.bones[settings.body_bone]
        head = _points(obj, [body.name], "head_local")[0]
        rest = (m / scale) @ mat3(body.matrix_local.to_3x3().normalized())
    rig = {
        "forward": forward,
        "body_head": head,
        "body_rest": rest,
        "legs": [],
        "reach_fraction": float(settings.reach),
        "frame": m,
        "scale": scale,
        "on_object": on_object,
    }
    for k in LEG_NAMES:
        heads, tail = leg_points(obj, chains[k])
        rig["legs"].append(
            {
                "heads": np.ascontiguousarray(heads),
                "tail": np.ascontiguousarray(tail),
                "limit_min": np.radians([b.limit_min for b in legs[k].bones]).astype(np.float64),
                "limit_max": np.radians([b.limit_max for b in legs[k].bones]).astype(np.float64),
                "stiffness": np.array([b.stiffness for b in legs[k].bones], dtype=np.float64),
            }
        )
    why = native.module().gait_validate_rig(rig)
    if why:
        raise ValueError(why)
    return rig, chains


def hinge_axes(obj, chains, forward):
    """Each leg bone's hinge axis in its own rest space: the body's lateral axis (given
    in the gait frame, mapped back into armature space)."""
    m, scale = gait_frame(obj)
    lateral = (m / scale).T @ np.cross([0.0, 0.0, 1.0], forward)
    axes = {}
    for k in LEG_NAMES:
        for name in chains[k]:
            mb = mat3(obj.data.bones[name].matrix_local.to_3x3().normalized())
            a = mb.T @ lateral
            axes[name] = a / np.linalg.norm(a)
    return axes


def leg_length(rig):
    """Hip height above the feet (m, gait frame): the length Froude numbers use."""
    hind = [rig["legs"][2], rig["legs"][3]]
    return float(max(leg["heads"][0][2] - leg["tail"][2] for leg in hind))


def neutral_offsets(rig):
    return np.array(
        [float((leg["tail"] - leg["heads"][0]) @ rig["forward"]) for leg in rig["legs"]]
    )


def hinge_channel(axis):
    """How a hinge about `axis` (unit, in the bone's rest space) is keyed: ("X", sign)
    when it is the bone's own X axis (one Euler channel), else ("QUATERNION", 0)."""
    if abs(abs(float(axis[0])) - 1.0) < 1e-6:
        return "X", (1.0 if axis[0] > 0 else -1.0)
    return "QUATERNION", 0.0
