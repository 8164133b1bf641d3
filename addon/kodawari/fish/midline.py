"""The body's control axis: along the fish's real mid-line, snout to tail tip.

The axis runs through the centroids of cross-sections taken across the head
axis, so a curved or asymmetric body binds along its own middle instead of a
bounding-box line (the issue's "User flow").
"""

import numpy as np

AXES = {
    "POS_X": (1.0, 0.0, 0.0),
    "NEG_X": (-1.0, 0.0, 0.0),
    "POS_Y": (0.0, 1.0, 0.0),
    "NEG_Y": (0.0, -1.0, 0.0),
    "POS_Z": (0.0, 0.0, 1.0),
    "NEG_Z": (0.0, 0.0, -1.0),
}
OPPOSITE = {
    "POS_X": "NEG_X",
    "NEG_X": "POS_X",
    "POS_Y": "NEG_Y",
    "NEG_Y": "POS_Y",
    "POS_Z": "NEG_Z",
    "NEG_Z": "POS_Z",
}
LABEL = {"POS_X": "+X", "NEG_X": "-X", "POS_Y": "+Y", "NEG_Y": "-Y", "POS_Z": "+Z", "NEG_Z": "-Z"}


def body_frame(head_axis):
    """(head, up, side) unit vectors, object space: up is +Z (+Y for a fish along Z)."""
    head = np.array(AXES[head_axis])
    up = np.array((0.0, 1.0, 0.0)) if abs(head[2]) > 0.5 else np.array((0.0, 0.0, 1.0))
    side = np.cross(up, head)
    return head, up, side / np.linalg.norm(side)


def _slice_sizes(verts, axis_index, bins):
    """Per-slice cross-section size (product of the two other extents) along one axis."""
    coord = verts[:, axis_index].astype(np.float64)
    lo, hi = coord.min(), coord.max()
    index = np.minimum(((coord - lo) / max(hi - lo, 1e-12) * bins).astype(np.int64), bins - 1)
    others = [i for i in range(3) if i != axis_index]
    sizes = np.zeros(bins)
    order = np.argsort(index, kind="stable")
    sorted_index = index[order]
    starts = np.searchsorted(sorted_index, np.arange(bins))
    ends = np.searchsorted(sorted_index, np.arange(bins), side="right")
    for b in range(bins):
        if ends[b] > starts[b]:
            chunk = verts[order[starts[b] : ends[b]]][:, others]
            extent = chunk.max(axis=0) - chunk.min(axis=0)
            sizes[b] = float(extent[0]) * float(extent[1])
    return sizes


def guess_head_axis(verts):
    """(axis name, sentence for the report). The longest extent is the body; the head
    is the end nearer the thickest cross-section (fish are thickest in the front half,
    and the tail narrows to the peduncle)."""
    extent = verts.max(axis=0) - verts.min(axis=0)
    axis_index = int(np.argmax(extent))
    sizes = _slice_sizes(verts, axis_index, 24)
    # Mass-like weighting: where along the axis the body's cross-sections sit.
    centres = (np.arange(24) + 0.5) / 24.0
    weight = sizes.sum()
    bias = float((sizes * centres).sum() / weight) if weight > 0 else 0.5
    positive = bias > 0.5
    name = ("POS_" if positive else "NEG_") + "XYZ"[axis_index]
    confidence = "clearly" if abs(bias - 0.5) > 0.03 else "only slightly (check it)"
    reason = (
        f"head guessed along {LABEL[name]}: the body is longest along {'XYZ'[axis_index]} and "
        f"{confidence} thicker toward that end; flip Head Axis if the fish swims backward"
    )
    return name, reason


def midline_points(verts, head_axis, count, slices=None):
    """Control points (count, 3) float64 along the mid-line, snout first, and the body length."""
    head, _, _ = body_frame(head_axis)
    v = verts.astype(np.float64)
    along = v @ head
    lo, hi = float(along.min()), float(along.max())
    length = hi - lo
    slices = slices or max(4 * count, 32)
    index = np.minimum(
        ((hi - along) / max(length, 1e-12) * slices).astype(np.int64), slices - 1
    )  # 0 = snout
    counts = np.bincount(index, minlength=slices).astype(np.float64)
    sums = np.stack(
        [np.bincount(index, weights=v[:, c], minlength=slices) for c in range(3)], axis=1
    )
    filled = counts > 0
    centroids = np.zeros((slices, 3))
    centroids[filled] = sums[filled] / counts[filled, None]
    # Empty slices (sparse meshes) borrow from their neighbours.
    positions = np.arange(slices, dtype=np.float64)
    for c in range(3):
        centroids[:, c] = np.interp(positions, positions[filled], centroids[filled, c])
    # Smooth the centroid line ([1, 2, 1]) so single fins do not kink the axis.
    smooth = centroids.copy()
    smooth[1:-1] = 0.25 * centroids[:-2] + 0.5 * centroids[1:-1] + 0.25 * centroids[2:]
    # Replace the along-axis coordinate by the slice centre, and pin the ends to the extremes.
    t = (positions + 0.5) / slices
    t[0], t[-1] = 0.0, 1.0
    line = smooth - np.outer(smooth @ head, head) + np.outer(hi - t * length, head)
    # Resample evenly by arc length.
    seg = np.linalg.norm(np.diff(line, axis=0), axis=1)
    arc = np.concatenate([[0.0], np.cumsum(seg)])
    targets = np.linspace(0.0, arc[-1], count)
    points = np.stack([np.interp(targets, arc, line[:, c]) for c in range(3)], axis=1)
    # Body length: snout to tail tip along the head axis (what "L" means in the literature).
    return np.ascontiguousarray(points), float(length)
