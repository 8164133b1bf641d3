"""Automatic fin finder: thin parts standing away from the body's core.

A vertex is "thin" when a ray cast inward (against its normal) leaves the mesh
again within a small fraction of the body length — a fin is a plate, the body is
a solid. Thin vertices farther from the mid-line than the body's core at that
cross-section are fin vertices; where they sit around the body names the fin
(caudal behind, dorsal above, anal / pelvic below, pectoral at the sides). Runs
once, on request; never per frame.
"""

import numpy as np
from mathutils import Vector
from mathutils.bvhtree import BVHTree

THIN = 0.03  # fin plates are thinner than this fraction of body length
CORE_FACTOR = 1.05  # and stand farther out than the core radius of their cross-section
MIN_FIN_VERTICES = 8
SLICES = 24


def _thickness(mesh, verts, body_length):
    normals = np.empty((len(mesh.vertices), 3), dtype=np.float32)
    mesh.vertices.foreach_get("normal", normals.reshape(-1))
    polygons = [tuple(p.vertices) for p in mesh.polygons]
    if not polygons:
        return np.zeros(len(verts))
    tree = BVHTree.FromPolygons(verts.tolist(), polygons, all_triangles=False, epsilon=0.0)
    eps = 1e-4 * body_length
    reach = 0.5 * body_length
    thickness = np.zeros(len(verts))
    for i, (v, n) in enumerate(zip(verts, normals)):
        inward = Vector((-float(n[0]), -float(n[1]), -float(n[2])))
        if inward.length == 0:
            continue
        point = Vector((float(v[0]), float(v[1]), float(v[2])))
        # Inward first; a mesh with flipped normals finds its far side the other way.
        # An open plate (no far side within reach either way) counts as thin.
        for direction in (inward, -inward):
            hit = tree.ray_cast(point + direction * eps, direction, reach)
            if hit[0] is not None:
                thickness[i] = hit[3] + eps
                break
    return thickness


def _axis_coordinates(verts, axis):
    """Arc fraction along the axis polyline, offset from it, for every vertex."""
    v = verts.astype(np.float64)
    starts, seg = axis[:-1], np.diff(axis, axis=0)
    seg_len = np.linalg.norm(seg, axis=1)
    arc0 = np.concatenate([[0.0], np.cumsum(seg_len)])[:-1]
    best = np.full(len(v), np.inf)
    arc = np.zeros(len(v))
    offset = np.zeros_like(v)
    for k in range(len(seg)):
        t = np.clip(((v - starts[k]) @ seg[k]) / (seg_len[k] ** 2), 0.0, 1.0)
        closest = starts[k] + t[:, None] * seg[k]
        d = np.linalg.norm(v - closest, axis=1)
        better = d < best
        best[better] = d[better]
        arc[better] = arc0[k] + t[better] * seg_len[k]
        offset[better] = (v - closest)[better]
    return arc / seg_len.sum(), offset, best


def find_fins(obj, rig):
    """[(group name, kind, vertex indices)] found on the object's rest mesh."""
    verts = rig.rest
    length = rig.body_length
    thickness = _thickness(obj.data, verts, length)
    s, offset, radius = _axis_coordinates(verts, rig.axis_rest)
    thin = thickness < THIN * length
    slice_index = np.minimum((s * SLICES).astype(np.int64), SLICES - 1)
    core = np.zeros(SLICES)
    for b in range(SLICES):
        solid = (slice_index == b) & ~thin
        if solid.any():
            core[b] = (
                float(np.median(radius[solid])) if solid.sum() > 3 else float(radius[solid].max())
            )
    candidate = thin & (radius > CORE_FACTOR * core[slice_index])
    up_part = offset @ rig.up
    side_part = offset @ rig.side
    kinds = np.full(len(verts), "", dtype=object)
    upward = up_part > 0.5 * np.abs(side_part)
    downward = up_part < -0.5 * np.abs(side_part)
    kinds[candidate & (s > 0.85)] = "CAUDAL"
    rest_candidates = candidate & (s <= 0.85)
    kinds[rest_candidates & upward] = "DORSAL"
    kinds[rest_candidates & downward & (s >= 0.5)] = "ANAL"
    kinds[rest_candidates & downward & (s < 0.5)] = "PELVIC"
    kinds[rest_candidates & ~upward & ~downward] = "PECTORAL"
    found = []
    for kind in ("CAUDAL", "DORSAL", "ANAL", "PELVIC", "PECTORAL"):
        indices = np.flatnonzero(kinds == kind)
        if len(indices) >= MIN_FIN_VERTICES:
            found.append((f"fin_{kind.lower()}", kind, indices))
    return found
