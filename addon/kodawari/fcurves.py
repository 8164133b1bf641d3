"""Fast F-curve writing, and the one place that knows how actions store F-curves.

Blender 4.4 gave actions slots and layers; `Action.fcurves` is legacy there and
gone in 5.0. Everything else in the add-on goes through these functions.
"""

import bpy
import numpy as np

_SLOTTED = bpy.app.version >= (4, 4, 0)


def ensure_action(id_block, name):
    """The action animating id_block, creating and assigning one if it has none."""
    anim = id_block.animation_data or id_block.animation_data_create()
    if anim.action is None:
        anim.action = bpy.data.actions.new(name)
    action = anim.action
    if _SLOTTED and anim.action_slot is None:
        slot = action.slots.new(id_type=id_block.id_type, name=id_block.name)
        anim.action_slot = slot
    return action


def _channelbag(action, id_block, create):
    """The channel bag holding id_block's F-curves in a layered action (4.4+)."""
    slot = id_block.animation_data.action_slot if id_block.animation_data else None
    if slot is None:
        return None
    for layer in action.layers:
        for strip in layer.strips:
            bag = strip.channelbag(slot)
            if bag is not None:
                return bag
    if not create:
        return None
    layer = action.layers[0] if len(action.layers) else action.layers.new("Layer")
    strip = layer.strips[0] if len(layer.strips) else layer.strips.new(type="KEYFRAME")
    return strip.channelbag(slot, ensure=True)


def action_fcurves(action, id_block):
    """The F-curves of `action` that animate id_block (a list, possibly empty)."""
    if not _SLOTTED:
        return list(action.fcurves)
    bag = _channelbag(action, id_block, create=False)
    return list(bag.fcurves) if bag is not None else []


def find_fcurve(action, id_block, data_path, index=0):
    for fcurve in action_fcurves(action, id_block):
        if fcurve.data_path == data_path and fcurve.array_index == index:
            return fcurve
    return None


def ensure_fcurve(action, id_block, data_path, index=0, group=""):
    """An empty F-curve for (data_path, index), replacing any existing one."""
    if _SLOTTED:
        fcurves = _channelbag(action, id_block, create=True).fcurves
    else:
        fcurves = action.fcurves
    old = find_fcurve(action, id_block, data_path, index)
    if old is not None:
        fcurves.remove(old)
    if _SLOTTED:
        fcurve = fcurves.new(data_path, index=index)
        if group:
            bag = _channelbag(action, id_block, create=True)
            grp = bag.groups.get(group) or bag.groups.new(group)
            fcurve.group = grp
        return fcurve
    return fcurves.new(data_path, index=index, action_group=group)


def write_keys(fcurve, frames, values, interpolation="LINEAR"):
    """Replace fcurve's keys by (frames[i], values[i]) in one bulk write."""
    frames = np.asarray(frames, dtype=np.float32)
    values = np.asarray(values, dtype=np.float32)
    if frames.shape != values.shape or frames.ndim != 1:
        raise ValueError("frames and values must be 1-D arrays of the same length")
    points = fcurve.keyframe_points
    if len(points):
        points.clear()
    n = len(frames)
    points.add(n)
    co = np.empty(2 * n, dtype=np.float32)
    co[0::2] = frames
    co[1::2] = values
    points.foreach_set("co", co)
    interp_enum = (
        bpy.types.Keyframe.bl_rna.properties["interpolation"].enum_items[interpolation].value
    )
    points.foreach_set("interpolation", np.full(n, interp_enum, dtype=np.int32))
    fcurve.update()


def write_channels(action, id_block, data_path, frames, values, group="", interpolation="LINEAR"):
    """Bake a (F, C) array of values into C F-curves of data_path (indices 0..C-1)."""
    values = np.asarray(values, dtype=np.float32)
    if values.ndim == 1:
        values = values[:, None]
    curves = []
    for index in range(values.shape[1]):
        fcurve = ensure_fcurve(action, id_block, data_path, index, group)
        write_keys(fcurve, frames, np.ascontiguousarray(values[:, index]), interpolation)
        curves.append(fcurve)
    return curves


def remove_fcurve(action, id_block, fcurve):
    """Remove one F-curve of id_block from `action` (legacy or slotted)."""
    if not _SLOTTED:
        action.fcurves.remove(fcurve)
        return
    bag = _channelbag(action, id_block, create=False)
    if bag is not None:
        bag.fcurves.remove(fcurve)


def read_keys(fcurve):
    """(frames, values) of an F-curve's keys as float32 arrays, in one bulk read."""
    points = fcurve.keyframe_points
    co = np.empty(2 * len(points), dtype=np.float32)
    points.foreach_get("co", co)
    return co[0::2].copy(), co[1::2].copy()


def current_slot_identifier(id_block):
    """The identifier of the action slot id_block uses (None before 4.4 or when unset)."""
    anim = id_block.animation_data
    if not _SLOTTED or anim is None or anim.action_slot is None:
        return None
    return anim.action_slot.identifier


def assign_action(id_block, action, slot_identifier=None):
    """Make `action` animate id_block, on the slot with slot_identifier when given
    (4.4+), else on its only slot, else a new one. action=None unassigns."""
    anim = id_block.animation_data or id_block.animation_data_create()
    anim.action = action
    if action is None or not _SLOTTED:
        return
    slot = None
    for candidate in action.slots:
        if slot_identifier is not None and candidate.identifier == slot_identifier:
            slot = candidate
    if slot is None and slot_identifier is None and len(action.slots) == 1:
        slot = action.slots[0]
    if slot is None:
        slot = action.slots.new(id_type=id_block.id_type, name=id_block.name)
    anim.action_slot = slot


_KEY_VECTORS = ("co", "handle_left", "handle_right")
_KEY_ENUMS = ("interpolation", "handle_left_type", "handle_right_type", "easing")


def copy_keys(fcurve):
    """Everything of an F-curve's keys (positions, handles, interpolation, easing) and
    its extrapolation, read in bulk, for copy_into."""
    points = fcurve.keyframe_points
    n = len(points)
    data = {
        "data_path": fcurve.data_path,
        "index": fcurve.array_index,
        "group": fcurve.group.name if fcurve.group else "",
        "extrapolation": fcurve.extrapolation,
    }
    for name in _KEY_VECTORS:
        data[name] = np.empty(2 * n, dtype=np.float32)
        points.foreach_get(name, data[name])
    for name in _KEY_ENUMS:
        data[name] = np.empty(n, dtype=np.int32)
        points.foreach_get(name, data[name])
    return data


def copy_into(action, id_block, data):
    """Recreate an F-curve saved by copy_keys in `action` (animating id_block)."""
    fcurve = ensure_fcurve(action, id_block, data["data_path"], data["index"], data["group"])
    points = fcurve.keyframe_points
    points.add(len(data["interpolation"]))
    for name in _KEY_VECTORS + _KEY_ENUMS:
        points.foreach_set(name, data[name])
    fcurve.extrapolation = data["extrapolation"]
    fcurve.update()
    return fcurve
