"""Checks run before an operator touches anything; each returns an error sentence or None."""

import numpy as np

from .. import bulk

MIN_VERTICES = 4
MAX_FIN_SHARE = 0.5  # a "fin" holding more than half the mesh is the body, not a fin


def swim_target(obj):
    if obj is None:
        return "Select a mesh object first (no active object)"
    if obj.type != "MESH":
        return (
            f"'{obj.name}' is a {obj.type.lower()}, not a mesh: Fish Swim deforms mesh objects only"
        )
    if obj.mode != "OBJECT":
        return f"'{obj.name}' is in {obj.mode.lower().replace('_', ' ')} mode: switch to Object Mode first"
    if len(obj.data.vertices) < MIN_VERTICES:
        return f"'{obj.name}' has {len(obj.data.vertices)} vertices; Fish Swim needs at least {MIN_VERTICES}"
    scale = tuple(obj.scale)
    if min(scale) <= 0:
        return (
            f"'{obj.name}' has a negative or zero scale {tuple(round(s, 4) for s in scale)}: "
            f"apply the scale (Ctrl+A) first"
        )
    if max(scale) - min(scale) > 1e-4 * max(abs(s) for s in scale):
        return (
            f"'{obj.name}' has a non-uniform scale {tuple(round(s, 4) for s in scale)}: "
            f"apply the scale (Ctrl+A) first so the body bends without shearing"
        )
    if obj.data.shape_keys is not None:
        return (
            f"'{obj.name}' already has shape keys: Fish Swim writes its own shape key on a clean mesh; "
            f"apply or remove the existing ones first"
        )
    if len(obj.modifiers):
        names = ", ".join(m.name for m in obj.modifiers)
        return f"'{obj.name}' has modifiers ({names}): apply or remove them before adding Fish Swim"
    return None


def frequency(value):
    if not np.isfinite(value) or value < 0:
        return f"Frequency must be zero or more tail beats per second, got {value}"
    return None


def fin_group(obj, group_name, existing_fins, weights=None):
    """(error, weights): the vertex group must exist, hold vertices and not be most of the mesh."""
    if not group_name:
        return "Give the vertex group that holds the fin's vertices", None
    if group_name not in obj.vertex_groups:
        known = ", ".join(g.name for g in obj.vertex_groups) or "none"
        return f"'{obj.name}' has no vertex group '{group_name}' (groups: {known})", None
    if any(f.vertex_group == group_name for f in existing_fins):
        return f"Vertex group '{group_name}' is already a fin of '{obj.name}'", None
    if weights is None:
        weights = bulk.vertex_group_weights(obj, group_name)
    members = int(np.count_nonzero(weights > 0))
    if members == 0:
        return f"Vertex group '{group_name}' is empty: assign the fin's vertices to it first", None
    if members < MIN_VERTICES:
        return (
            f"Vertex group '{group_name}' has {members} vertices; a fin needs at least {MIN_VERTICES}",
            None,
        )
    share = members / len(weights)
    if share > MAX_FIN_SHARE:
        return (
            f"Vertex group '{group_name}' covers {share:.0%} of the mesh: a fin must be a small part "
            f"(at most {MAX_FIN_SHARE:.0%}), not the body"
        ), None
    return None, weights
