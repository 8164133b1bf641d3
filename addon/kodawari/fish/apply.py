"""Apply Fish Swim: like applying a modifier, the shape the fish has at the current
frame becomes its mesh and the swim is removed (one undo step takes it back)."""

import bpy
from bpy.app.translations import pgettext_tip as tip_

from .. import bulk
from . import ops, runtime


class KODAWARI_OT_swim_apply(bpy.types.Operator):
    """Make the fish's shape at the current frame its mesh and remove the swim, like applying a modifier"""

    bl_idname = "kodawari.swim_apply"
    bl_label = "Apply Fish Swim"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = ops._active_mesh(context)
        error = _refusal(obj)
        if error:
            self.report({"ERROR"}, error)
            return {"CANCELLED"}
        try:
            positions = runtime.positions(obj, context.scene).copy()
        except ValueError as exc:
            self.report({"ERROR"}, tip_("Cannot apply the swim of '{}': {}").format(obj.name, exc))
            return {"CANCELLED"}
        with runtime.batch(obj):
            ops.remove_swim(obj)
        bulk.set_vertex_positions(obj.data, positions)
        obj.data.update()
        self.report(
            {"INFO"},
            tip_("Fish Swim applied to '{}': the shape at frame {} is now its mesh").format(
                obj.name, context.scene.frame_current
            ),
        )
        return {"FINISHED"}


def _refusal(obj):
    if obj is None or obj.type != "MESH":
        return tip_("Select the swimming mesh object first")
    settings = obj.kodawari_swim
    if settings.baked != "NONE":
        return tip_("'{}' is baked: remove or free the bake before applying the swim").format(
            obj.name
        )
    if not runtime.has_swim(obj):
        return tip_("'{}' has no Fish Swim to apply").format(obj.name)
    keys = obj.data.shape_keys
    # An older file's swim key and the Basis added with it are the swim's own.
    ours = {runtime.SHAPE_KEY, keys.reference_key.name} if runtime.swim_key_block(obj) else set()
    others = [b.name for b in (keys.key_blocks if keys is not None else ()) if b.name not in ours]
    if others:
        return tip_(
            "Cannot apply to a mesh with other shape keys ({}): apply or remove them first, "
            "as for any modifier"
        ).format(", ".join(others))
    return None


CLASSES = (KODAWARI_OT_swim_apply,)
