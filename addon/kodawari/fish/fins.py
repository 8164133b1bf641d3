"""Fin set-up (docs/algorithms.md §2.4-§2.5): each fin part bound once in the core.

A fin's vertices come from a vertex group. How far each stands from the body is
its path across the fin from where it meets the body (fin_reach, native); the
fin's motion swings every vertex about its own root point by that reach, faded
in from 0 at the root (so root vertices move exactly with the body and the fin
never tears from it) to the full motion over the first root_blend of the fin
(an undulating fin: over its whole height). A swinging fin (FLAP, UP_DOWN) fades
in over a reach that grows slowly along its motion (swing_squash), so no edge
stretches past 1.5x. The core (kodawari_native.FinPart) turns the motion with the
body's rotation at the fin root every frame.
"""

import numpy as np
from bpy.app.translations import pgettext_tip as tip_


class FinPart:
    """One side of one fin, bound for motion in the core (kodawari_native.FinPart): each
    vertex swings about its own root point, faded in from the body (a group holding a
    left and a right pectoral fin becomes two parts that beat as mirror images)."""

    def __init__(self, fin_index, indices, weights, rest, reach, root, tip, frame, base, fade, kn):
        self.fin_index = fin_index
        self.indices = indices  # int64 (M,) vertex indices into the mesh
        self.rest = rest  # float32 (M, 3) rest positions
        self.tangent, self.side, self.up = frame
        self.root = root  # float64 (3,) where the fin meets the body
        outward = tip - root
        self.outward = outward / np.linalg.norm(outward)
        self.feather_on_power, self.feather_sign = _blade_facing(rest, outward, frame, kn)
        height = float(reach.max()) if len(reach) else 1.0
        self.binding = kn.FinPart(
            rest,
            np.ascontiguousarray(reach, dtype=np.float64),
            np.ascontiguousarray(weights, dtype=np.float64),
            np.asarray(root, dtype=np.float64),
            np.asarray(outward, dtype=np.float64),
            *frame,
            max(height, 1e-9),
            max(base[1] - base[0], 1e-9),
            base[0],
            fade,
        )
        self.out = np.empty_like(rest)


def _up_hint(axis, up, side):
    direction = axis[-1] - axis[0]
    direction = direction / np.linalg.norm(direction)
    return up if abs(float(direction @ up)) < 0.9 else side


def _blade_facing(rest, direction, frame, kn):
    """(feather on the power stroke?, roll sign): compares the modelled blade's normal
    (least-variance direction of its vertices) with the flap stroke direction."""
    stroke = kn.swim_flap_stroke_direction(direction, *frame)
    centred = rest.astype(np.float64) - rest.mean(axis=0)
    normal = np.linalg.svd(centred, full_matrices=False)[2][-1]
    facing = abs(float(normal @ stroke))
    on_power = facing < 0.7  # modelled edge-on: roll it to face the stroke on the power stroke
    # Roll toward the stroke direction (rotation about the fin axis, right-handed).
    sign = 1.0 if float(np.cross(normal, stroke) @ direction) >= 0 else -1.0
    return on_power, sign


def body_frame_at(point, body_axis, up):
    """Tailward tangent, side and up of the body axis (control polygon) nearest `point`."""
    seg_start = body_axis[:-1]
    seg = body_axis[1:] - seg_start
    lengths2 = np.einsum("ij,ij->i", seg, seg)
    t = np.clip(np.einsum("ij,ij->i", point - seg_start, seg) / lengths2, 0.0, 1.0)
    closest = seg_start + t[:, None] * seg
    k = int(np.argmin(np.linalg.norm(closest - point, axis=1)))
    tangent = seg[k] / np.sqrt(lengths2[k])
    u = up - (up @ tangent) * tangent
    u = u / np.linalg.norm(u)
    side = np.cross(tangent, u)
    return (tangent, side, u), closest[k]


def _outward(kind, centroid_offset, frame):
    tangent, side, up = frame
    if kind == "CAUDAL":
        return tangent
    if kind == "DORSAL":
        return up
    if kind == "ANAL":
        return -up
    across = centroid_offset - (centroid_offset @ tangent) * tangent
    norm = np.linalg.norm(across)
    if norm < 1e-9:
        return side if kind == "PECTORAL" else -up
    return across / norm


def fin_reach(rest, edges, in_fin, body_length, kn, squash=None):
    """Per vertex: how far across its fin it stands from the body (path length along the
    fin's edges from where it meets the body; 0 on the body). squash: float32 (N, 9)
    (swing_squash): the reach then grows slowly along each swinging part's motion, so no
    edge stretches (docs/algorithms.md §2.4). Native."""
    reach, _source = kn.swim_fin_reach(
        np.ascontiguousarray(rest, dtype=np.float32),
        edges,
        np.ascontiguousarray(in_fin, dtype=bool),
        1e-4 * body_length,
        squash,
    )
    return reach


SWINGING = ("FLAP", "UP_DOWN")
ROWING_KINDS = ("PECTORAL", "PELVIC")  # paired fins row: their FLAP feathers freely


def swing_squash(parts, fins, count):
    """float32 (count, 9): per vertex of a swinging part, the projector (3x3, row-major)
    onto the directions its motion moves it in: the swing direction, and for a rowing
    fin's FLAP everything across its outward direction (the feathering roll turns the
    blade about it). Zero elsewhere; None when no part swings. For fin_reach's squash."""
    squash = np.zeros((count, 9), dtype=np.float32)
    for part in parts:
        fin = fins[part.fin_index]
        if fin.motion not in SWINGING:
            continue
        if fin.motion == "FLAP" and fin.kind in ROWING_KINDS:
            projector = np.eye(3) - np.outer(part.outward, part.outward)
        else:
            s = part.binding.swing_direction(fin.motion)
            projector = np.outer(s, s)
        squash[part.indices] = projector.reshape(-1)
    return squash if squash.any() else None


def split_sides(kind, points, axis_point, frame):
    """Masks of the parts of a fin group: pectoral and pelvic groups holding both a
    left and a right fin split by side; other kinds stay whole."""
    whole = [np.ones(len(points), dtype=bool)]
    if kind not in ("PECTORAL", "PELVIC"):
        return whole
    side_coord = (points - axis_point) @ frame[1]
    left, right = side_coord > 0, side_coord <= 0
    if min(left.sum(), right.sum()) >= max(3, 0.1 * len(points)):
        return [left, right]
    return whole


def build_parts(
    fin_index, fin, group_weights, verts, body_axis, up, kn, reach_all=None, swing_reach_all=None
):
    """FinParts of one fin setting; raises ValueError with a readable reason.
    swing_reach_all: fin_reach squashed along each swinging part's motion (swing_squash),
    the reach its swing fades in over; the part's root and tip still come from reach_all."""
    indices = np.flatnonzero(group_weights > 0.0)
    if len(indices) < 4:
        raise ValueError(
            tip_("vertex group '{}' has fewer than 4 vertices").format(fin.vertex_group)
        )
    points_all = verts[indices].astype(np.float64)
    parts = []
    centroid_all = points_all.mean(axis=0)
    frame_all, axis_point_all = body_frame_at(centroid_all, body_axis, up)
    for mask in split_sides(fin.kind, points_all, axis_point_all, frame_all):
        points = points_all[mask]
        part_indices = indices[mask]
        centroid = points.mean(axis=0)
        frame, axis_point = body_frame_at(centroid, body_axis, up)
        # How far out each vertex is: its (smoothed) path across the fin from where it
        # meets the body (fin_reach; 0 at the root), else its reach along the kind's
        # outward direction.
        reach = None
        if reach_all is not None and np.all(np.isfinite(reach_all[part_indices])):
            reach = reach_all[part_indices]
        if reach is None:
            reach = (points - centroid) @ _outward(fin.kind, centroid - axis_point, frame)
        lo, hi = float(reach.min()), float(reach.max())
        if hi - lo < 1e-6:
            raise ValueError(
                tip_("vertex group '{}' does not stand out from the body").format(fin.vertex_group)
            )
        r = (reach - lo) / (hi - lo)  # 0 at the root, 1 at the fin's outer edge
        root = points[r <= 0.1].mean(axis=0)
        tip = points[r >= 0.9].mean(axis=0)
        if np.linalg.norm(tip - root) < 1e-6:
            tip = root + (hi - lo) * _outward(fin.kind, centroid - axis_point, frame)
        along = points @ frame[0]
        base = (float(along.min()), float(along.max()))
        if fin.motion == "UNDULATE" and base[1] - base[0] < 1e-6:
            raise ValueError(
                tip_("vertex group '{}' has no length along the body").format(fin.vertex_group)
            )
        # The motion fades in over the first root_blend of the fin (docs/algorithms.md
        # §2.5: the root must not move, or the fin tears from the body).
        # An undulation's sideways wave fades in over the whole fin height: over a short
        # root band it would shear the fin's base (its amplitude is a share of the height).
        # The fade is a smoothstep over a share of the fin's own height (not a fixed
        # distance), applied in the core, which also bends the swing along the fin.
        # A swing fades in over the reach squashed along its motion (swing_reach_all), which
        # grows at most 0.6 per unit length that way: across a thin fin's two faces or a
        # fan-shaped tail, a path length growing along the swing stretched edges 1.6x.
        if swing_reach_all is not None and np.all(np.isfinite(swing_reach_all[part_indices])):
            reach = swing_reach_all[part_indices]
            lo, hi = float(reach.min()), max(float(reach.max()), float(reach.min()) + 1e-9)
        span = 1.0 if fin.motion == "UNDULATE" else fin.root_blend
        fade = max(span, 1e-3) * (hi - lo)
        weights = group_weights[part_indices].astype(np.float64)
        rest = np.ascontiguousarray(verts[part_indices], dtype=np.float32)
        parts.append(
            FinPart(
                fin_index, part_indices, weights, rest, reach - lo, root, tip, frame, base, fade, kn
            )
        )
    return parts
