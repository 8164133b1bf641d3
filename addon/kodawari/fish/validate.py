"""Checks run before an operator touches anything; each returns an error sentence or None."""

import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import bulk

MIN_VERTICES = 4
MAX_FIN_SHARE = 0.5  # a "fin" holding more than half the mesh is the body, not a fin


def swim_target(obj):
    if obj is None:
        return tip_("Select a mesh object first (no active object)")
    if obj.type != "MESH":
        return tip_("'{}' is a {}, not a mesh: Fish Swim deforms mesh objects only").format(
            obj.name, obj.type.lower()
        )
    if obj.mode != "OBJECT":
        return tip_("'{}' is in {} mode: switch to Object Mode first").format(
            obj.name, obj.mode.lower().replace("_", " ")
        )
    if len(obj.data.vertices) < MIN_VERTICES:
        return tip_("'{}' has {} vertices; Fish Swim needs at least {}").format(
            obj.name, len(obj.data.vertices), MIN_VERTICES
        )
    scale = tuple(obj.scale)
    if min(scale) <= 0:
        return tip_("'{}' has a negative or zero scale {}: apply the scale (Ctrl+A) first").format(
            obj.name, tuple(round(s, 4) for s in scale)
        )
    if max(scale) - min(scale) > 1e-4 * max(abs(s) for s in scale):
        return tip_(
            "'{}' has a non-uniform scale {}: apply the scale (Ctrl+A) first so the body bends without shearing"
        ).format(obj.name, tuple(round(s, 4) for s in scale))
    if obj.data.shape_keys is not None:
        return tip_(
            "'{}' already has shape keys: Fish Swim binds the mesh's own shape; apply or remove the shape keys first"
        ).format(obj.name)
    if len(obj.modifiers):
        names = ", ".join(m.name for m in obj.modifiers)
        return tip_("'{}' has modifiers ({}): apply or remove them before adding Fish Swim").format(
            obj.name, names
        )
    return None


def frequency(value):
    if not np.isfinite(value) or value < 0:
        return tip_("Frequency must be zero or more tail beats per second, got {}").format(value)
    return None


def fin_group(obj, group_name, existing_fins, weights=None):
    """(error, weights): the vertex group must exist, hold vertices and not be most of the mesh."""
    if not group_name:
        return tip_("Give the vertex group that holds the fin's vertices"), None
    if group_name not in obj.vertex_groups:
        known = ", ".join(g.name for g in obj.vertex_groups) or "none"
        return tip_("'{}' has no vertex group '{}' (groups: {})").format(
            obj.name, group_name, known
        ), None
    if any(f.vertex_group == group_name for f in existing_fins):
        return tip_("Vertex group '{}' is already a fin of '{}'").format(group_name, obj.name), None
    if weights is None:
        weights = bulk.vertex_group_weights(obj, group_name)
    members = int(np.count_nonzero(weights > 0))
    if members == 0:
        return tip_("Vertex group '{}' is empty: assign the fin's vertices to it first").format(
            group_name
        ), None
    if members < MIN_VERTICES:
        return (
            tip_("Vertex group '{}' has {} vertices; a fin needs at least {}").format(
                group_name, members, MIN_VERTICES
            ),
            None,
        )
    share = members / len(weights)
    if share > MAX_FIN_SHARE:
        return (
            tip_(
                "Vertex group '{}' covers {:.0%} of the mesh: a fin must be a small part (at most {:.0%}), not the body"
            ).format(group_name, share, MAX_FIN_SHARE)
        ), None
    return None, weights
