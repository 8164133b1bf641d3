"""Reading a quadruped rig: finding its legs and body bone, its rest data for the
native planner, and the horse defaults. Set-up time only; no per-frame work here."""

import math
import re

import numpy as np

from .. import native
from .props import GAIT_NAMES, LEG_NAMES

_LEFT = re.compile(r"(\.|_|-| )(l|left)$|^left|left(\.|_|-| |$)", re.IGNORECASE)
_RIGHT = re.compile(r"(\.|_|-| )(r|right)$|^right|right(\.|_|-| |$)", re.IGNORECASE)
_FORE = re.compile(r"fore|front|arm", re.IGNORECASE)
_HIND = re.compile(r"hind|back|rear", re.IGNORECASE)

# The seed's joint ranges (4.x, degrees, each bone relative to its parent, the first
# relative to straight down, positive swinging the tip backward), widened where the
# seed's gallop snapshot cannot reach its own +-0.8 m (scapula +-3 deg, humerus +-1 deg).
HORSE_FORE_LIMITS = ((-55.0, -15.0), (60.0, 100.0), (-135.0, -5.0), (0.0, 120.0))
HORSE_HIND_LIMITS = ((40.0, 75.0), (-125.0, -55.0), (10.0, 125.0), (-135.0, 0.0))
HORSE_STIFFNESS = (0.1, 0.3, 0.5, 1.0)


def mat3(matrix):
    """A mathutils 3x3 (or the 3x3 of a 4x4) as a C-ordered float64 array, row by row
    (np.array(Matrix) changed memory order between Blender versions)."""
    return np.array([[float(matrix[i][j]) for j in range(3)] for i in range(3)], dtype=np.float64)


def side_of(name):
    if _LEFT.search(name):
        return "L"
    if _RIGHT.search(name):
        return "R"
    return None


def end_of(name):
    if _FORE.search(name):
        return "F"
    if _HIND.search(name):
        return "H"
    return None


def _chain_in(bones, members):
    """The longest parent -> child run of bones inside `members`, root first."""
    best = []
    for bone in bones:
        if bone.name not in members:
            continue
        if bone.parent is not None and bone.parent.name in members:
            continue  # not a chain start
        chain = [bone]
        while True:
            kids = [c for c in chain[-1].children if c.name in members]
            if not kids:
                break
            chain.append(max(kids, key=lambda c: _depth(c, members)))
        if len(chain) > len(best):
            best = chain
    return best


def _depth(bone, members):
    kids = [c for c in bone.children if c.name in members]
    return 1 + (max(_depth(c, members) for c in kids) if kids else 0)


def find_legs_by_name(armature):
    """{leg: [bone names root..foot]} for the legs whose names say side and end."""
    groups = {}
    for bone in armature.bones:
        side, end = side_of(bone.name), end_of(bone.name)
        if side and end:
            groups.setdefault(side + end, set()).add(bone.name)
    legs = {}
    for leg in LEG_NAMES:
        key = leg[0] + leg[1]
        if key in groups:
            chain = _chain_in(armature.bones, groups[key])
            if chain:
                legs[leg] = [b.name for b in chain]
    return legs


def find_legs_from_feet(armature, foot_names, body_name=None):
    """Four selected foot bones: each leg runs up from its foot while the parent is not
    the body (and not a parent of other legs); left/right and fore/hind by position."""
    feet = [armature.bones[n] for n in foot_names]
    shared = set.intersection(*[{p.name for p in f.parent_recursive} for f in feet]) if feet else set()
    legs_found = []
    for foot in feet:
        chain = [foot]
        while chain[-1].parent is not None and chain[-1].parent.name not in shared and len(chain) < 6:
            chain.append(chain[-1].parent)
        chain.reverse()
        legs_found.append(chain)
    heads = np.array([c[0].head_local for c in legs_found])
    order_y = np.argsort(heads[:, 1])  # Blender rigs face -Y: the two lowest y are fore
    legs = {}
    for rank, index in enumerate(order_y):
        end = "F" if rank < 2 else "H"
        side = "L" if heads[index, 0] > 0 else "R"
        legs[side + end] = [b.name for b in legs_found[index]]
    return legs


def find_body(armature, legs):
    """The deepest bone that is a parent of every leg root: it carries root motion."""
    roots = [armature.bones[chain[0]] for chain in legs.values()]
    if not roots:
        return None
    common = None
    for root in roots:
        ancestors = [p.name for p in root.parent_recursive]
        common = ancestors if common is None else [a for a in common if a in ancestors]
    return common[0] if common else None


def seed_angles(armature, names, forward):
    """Each bone's rest angle relative to its parent (the first: to straight down),
    degrees, positive swinging the tip backward (the seed's convention)."""
    previous = 0.0
    out = []
    for name in names:
        bone = armature.bones[name]
        d = np.array(bone.tail_local) - np.array(bone.head_local)
        absolute = math.degrees(math.atan2(-float(d @ forward), -float(d[2])))
        out.append(absolute - previous)
        previous = absolute
    return out


def forward_of(armature, legs):
    fore = np.mean([armature.bones[legs[k][0]].head_local for k in ("LF", "RF")], axis=0)
    hind = np.mean([armature.bones[legs[k][0]].head_local for k in ("LH", "RH")], axis=0)
    f = np.array([fore[0] - hind[0], fore[1] - hind[1], 0.0])
    n = np.linalg.norm(f)
    return f / n if n > 1e-9 else np.array([0.0, -1.0, 0.0])


def fill_horse_defaults(settings, armature, legs, body):
    """Horse defaults: the native table, the seed's joint ranges and stiffness for
    4-bone legs (generic ranges otherwise)."""
    kn = native.module()
    table = kn.gait_horse_table()
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
    settings.legs.clear()
    forward = forward_of(armature, legs) if all(k in legs for k in LEG_NAMES) else np.array([0.0, -1.0, 0.0])
    for leg in LEG_NAMES:
        item = settings.legs.add()
        item.name = leg
        names = legs.get(leg, [])
        rest = seed_angles(armature, names, forward) if names else []
        n = len(names)
        if n == 4:
            ranges = HORSE_FORE_LIMITS if leg.endswith("F") else HORSE_HIND_LIMITS
            stiffness = HORSE_STIFFNESS
        else:
            ranges = [(r - 60.0, r + 60.0) for r in rest]
            stiffness = tuple(np.linspace(0.1, 1.0, n)) if n > 1 else (1.0,) * n
        for k, name in enumerate(names):
            bone = item.bones.add()
            bone.name = name
            lo, hi = ranges[k]
            # Pose angles are measured from the rest pose: shift the seed's ranges.
            bone.limit_min = min(lo - rest[k], 0.0) if n != 4 else lo - rest[k]
            bone.limit_max = max(hi - rest[k], 0.0) if n != 4 else hi - rest[k]
            bone.stiffness = float(stiffness[k])


def table_dict(settings):
    kn = native.module()
    rows = []
    by_name = {e.name: e for e in settings.table}
    for name in GAIT_NAMES:
        entry = by_name.get(name)
        if entry is None:
            raise ValueError(f"the gait table has no {name} row: run Gait Setup")
        rows.append([float(getattr(entry, c)) for c in kn.GAIT_COLUMNS])
    return {"gaits": np.array(rows, dtype=np.float64), "use_froude": bool(settings.use_froude),
            "hysteresis": float(settings.hysteresis), "reach": float(settings.reach)}


def rig_dict(obj, settings):
    """The rig as the native planner reads it (armature space, radians); raises
    ValueError with a sentence for the user when something is missing."""
    armature = obj.data
    legs = {}
    for leg in settings.legs:
        names = [b.name for b in leg.bones]
        if len(names) < 2:
            raise ValueError(f"leg {leg.name} has {len(names)} bone(s); a leg needs 2 to 6")
        if len(names) > 6:
            raise ValueError(f"leg {leg.name} has {len(names)} bones; a leg needs 2 to 6")
        for n in names:
            if n not in armature.bones:
                raise ValueError(f"leg {leg.name}: bone '{n}' is not in the armature")
        legs[leg.name] = leg
    missing = [k for k in LEG_NAMES if k not in legs]
    if missing:
        raise ValueError(f"fewer than four legs set up (missing {', '.join(missing)}): run Gait Setup")
    if settings.body_bone not in armature.bones:
        raise ValueError("no body bone set (the bone carrying root motion): run Gait Setup")
    chains = {k: [b.name for b in legs[k].bones] for k in LEG_NAMES}
    forward = forward_of(armature, chains)
    body = armature.bones[settings.body_bone]
    rest = mat3(body.matrix_local.to_3x3().normalized())
    rig = {"forward": forward, "body_head": np.array(body.head_local, dtype=np.float64), "body_rest": rest,
           "legs": [], "reach_fraction": float(settings.reach)}
    for k in LEG_NAMES:
        bones = [armature.bones[n] for n in chains[k]]
        rig["legs"].append({
            "heads": np.array([b.head_local for b in bones], dtype=np.float64),
            "tail": np.array(bones[-1].tail_local, dtype=np.float64),
            "limit_min": np.radians([b.limit_min for b in legs[k].bones]).astype(np.float64),
            "limit_max": np.radians([b.limit_max for b in legs[k].bones]).astype(np.float64),
            "stiffness": np.array([b.stiffness for b in legs[k].bones], dtype=np.float64),
        })
    why = native.module().gait_validate_rig(rig)
    if why:
        raise ValueError(why)
    return rig, chains


def hinge_axes(obj, chains, forward):
    """Each leg bone's hinge axis in its own rest space: the body's lateral axis."""
    lateral = np.cross([0.0, 0.0, 1.0], forward)
    axes = {}
    for k in LEG_NAMES:
        for name in chains[k]:
            m = mat3(obj.data.bones[name].matrix_local.to_3x3().normalized())
            a = m.T @ lateral
            axes[name] = a / np.linalg.norm(a)
    return axes


def leg_length(rig):
    """Hip height above the feet: the length Froude numbers use."""
    hind = [rig["legs"][2], rig["legs"][3]]
    return float(max(leg["heads"][0][2] - leg["tail"][2] for leg in hind))


def neutral_offsets(rig):
    return np.array([float((leg["tail"] - leg["heads"][0]) @ rig["forward"]) for leg in rig["legs"]])


def hinge_channel(axis):
    """How a hinge about `axis` (unit, in the bone's rest space) is keyed: ("X", sign)
    when it is the bone's own X axis (one Euler channel), else ("QUATERNION", 0)."""
    if abs(abs(float(axis[0])) - 1.0) < 1e-6:
        return "X", (1.0 if axis[0] > 0 else -1.0)
    return "QUATERNION", 0.0
