"""Swimming along a Follow Path curve: the object advances along the curve at the
speed its tail beat implies, and its spine bends into the turns.

The Follow Path constraint places the object at a fraction of the path
(offset_factor, fixed-location mode) facing along the tangent. The spine bend
samples the same path behind and ahead of that point: each body control point
moves to where the path runs at its distance along the body, expressed in the
fish's own frame (forward = path tangent, up = world up made perpendicular).
"""

import bpy
import numpy as np

FORWARD = {
    "POS_X": "FORWARD_X",
    "NEG_X": "TRACK_NEGATIVE_X",
    "POS_Y": "FORWARD_Y",
    "NEG_Y": "TRACK_NEGATIVE_Y",
    "POS_Z": "FORWARD_Z",
    "NEG_Z": "TRACK_NEGATIVE_Z",
}


def follow_path(obj):
    for constraint in obj.constraints:
        if (
            constraint.type == "FOLLOW_PATH"
            and constraint.target is not None
            and constraint.target.type == "CURVE"
            and not constraint.mute
        ):
            return constraint
    return None


def polyline(curve_obj):
    """World-space points (K, 3) of the curve's evaluated first spline, and cumulative lengths."""
    depsgraph = bpy.context.evaluated_depsgraph_get()
    evaluated = curve_obj.evaluated_get(depsgraph)
    mesh = evaluated.to_mesh()
    try:
        points = np.empty((len(mesh.vertices), 3), dtype=np.float64)
        mesh.vertices.foreach_get("co", points.reshape(-1))
        cyclic = len(mesh.edges) == len(mesh.vertices) and len(points) > 2
    finally:
        evaluated.to_mesh_clear()
    world = np.array(curve_obj.matrix_world)
    points = points @ world[:3, :3].T + world[:3, 3]
    if cyclic:
        points = np.vstack([points, points[:1]])
    arc = np.concatenate([[0.0], np.cumsum(np.linalg.norm(np.diff(points, axis=0), axis=1))])
    return points, arc


def _point(points, arc, distance):
    d = float(np.clip(distance, 0.0, arc[-1]))
    k = int(np.clip(np.searchsorted(arc, d, side="right") - 1, 0, len(arc) - 2))
    span = arc[k + 1] - arc[k]
    t = (d - arc[k]) / span if span > 0 else 0.0
    return points[k] + t * (points[k + 1] - points[k])


def _at(points, arc, distance):
    """Point and unit tangent at an arc distance (clamped to the ends). The tangent is
    a central difference over one polyline segment each way, not the chord of the
    segment the point falls in (which tilts it by up to half a segment's turn)."""
    step = float(np.max(np.diff(arc))) if len(arc) > 1 else 0.0
    here = _point(points, arc, distance)
    tangent = _point(points, arc, distance + step) - _point(points, arc, distance - step)
    norm = np.linalg.norm(tangent)
    return here, tangent / norm if norm > 0 else tangent


def place(obj, follow, head_axis, distance_world, points, arc):
    """Set the constraint so the object sits `distance_world` along the path, head first."""
    forward = FORWARD[head_axis]
    if follow.forward_axis != forward:
        follow.forward_axis = forward
    if follow.up_axis != "UP_Z" and head_axis not in ("POS_Z", "NEG_Z"):
        follow.up_axis = "UP_Z"
    if not follow.use_curve_follow:
        follow.use_curve_follow = True
    if not follow.use_fixed_location:
        follow.use_fixed_location = True
    follow.offset_factor = (
        float(np.clip(distance_world / arc[-1], 0.0, 1.0)) if arc[-1] > 0 else 0.0
    )


def bent_rest_axis(rest_axis, head, up, side, scale, distance_world, points, arc):
    """The rest control axis bent along the path around the fish's place on it."""
    origin, tangent = _at(points, arc, distance_world)
    world_up = np.array((0.0, 0.0, 1.0))
    path_side = np.cross(world_up, tangent)
    if np.linalg.norm(path_side) < 1e-9:
        return rest_axis
    path_side /= np.linalg.norm(path_side)
    path_up = np.cross(tangent, path_side)
    bent = rest_axis.copy()
    for i, p in enumerate(rest_axis):
        along = float(p @ head)
        on_path = _point(points, arc, distance_world + along * scale)
        offset = (on_path - origin) / scale
        straight = along * head
        # Where the path runs, in the fish's frame, minus where the straight axis runs.
        local = (offset @ tangent) * head + (offset @ path_side) * side + (offset @ path_up) * up
        bent[i] = p + (local - straight)
    return np.ascontiguousarray(bent)
