"""The Kodawari Gait panel (Object properties of a set-up armature), in Blender's layout:
split labels with keyframe decorators, the everyday settings on top, and the rig, the
gait table and the legs in sub-panels that start closed."""

import bpy

from .. import in_use
from .props import GAIT_ITEMS, LEG_NAMES

GAIT_LABELS = {identifier: label for identifier, label, _ in GAIT_ITEMS}
LEG_LABELS = {
    "LF": "Left Fore Leg",
    "RF": "Right Fore Leg",
    "LH": "Left Hind Leg",
    "RH": "Right Hind Leg",
}


class _GaitPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return in_use.gait(context.object)


class KODAWARI_PT_gait(_GaitPanel, bpy.types.Panel):
    bl_label = "Kodawari Gait"

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        settings = context.object.kodawari_gait
        col = layout.column()
        col.prop(settings, "speed")
        col.prop(settings, "gait")
        col.prop(settings, "acceleration")
        row = layout.row(align=True)
        row.operator("kodawari.gait_bake", icon="REC")
        row.operator("kodawari.gait_report", icon="GRAPH")


class KODAWARI_PT_gait_rig(_GaitPanel, bpy.types.Panel):
    bl_label = "Rig and Ground"
    bl_parent_id = "KODAWARI_PT_gait"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        obj = context.object
        settings = obj.kodawari_gait
        col = layout.column()
        col.prop(settings, "root_motion")
        col.prop_search(settings, "body_bone", obj.data, "bones")
        col.prop(settings, "ground")
        col.prop(settings, "path")
        col.prop(settings, "ccd_iterations")
        layout.operator("kodawari.gait_setup", text="Find Legs Again", icon="FILE_REFRESH")


class KODAWARI_PT_gait_table(_GaitPanel, bpy.types.Panel):
    bl_label = "Gait Table"
    bl_parent_id = "KODAWARI_PT_gait"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        settings = context.object.kodawari_gait
        col = layout.column()
        col.prop(settings, "use_froude")
        col.prop(settings, "hysteresis")
        col.prop(settings, "reach", slider=True)


def _entry(settings, name):
    for entry in settings.table:
        if entry.name == name:
            return entry
    return None


def _gait_row_panel(name):
    """One closed sub-panel per gait of the table (Walk, Trot, ...)."""

    class Row(_GaitPanel, bpy.types.Panel):
        bl_label = GAIT_LABELS[name]
        bl_parent_id = "KODAWARI_PT_gait_table"
        bl_options = {"DEFAULT_CLOSED"}

        @classmethod
        def poll(cls, context):
            return (
                in_use.gait(context.object)
                and _entry(context.object.kodawari_gait, name) is not None
            )

        def draw_header(self, context):
            self.layout.prop(_entry(context.object.kodawari_gait, name), "use_in_auto", text="")

        def draw(self, context):
            layout = in_use.split_layout(self.layout)
            settings = context.object.kodawari_gait
            entry = _entry(settings, name)
            col = layout.column()
            col.prop(entry, "duty_factor", slider=True)
            col.prop(entry, "duty_factor_top", slider=True)
            col.prop(entry, "phase_fore_hind", slider=True)
            col.prop(entry, "phase_left_right", slider=True)
            col = layout.column()
            col.prop(entry, "swing_time")
            col.prop(entry, "swing_height")
            col.prop(entry, "swing_peak", slider=True)
            col = layout.column()
            col.prop(entry, "bob")
            col.prop(entry, "bobs_per_cycle")
            col.prop(entry, "froude_max" if settings.use_froude else "speed_max")

    Row.__name__ = Row.bl_idname = f"KODAWARI_PT_gait_table_{name.lower()}"
    return Row


class KODAWARI_PT_gait_legs(_GaitPanel, bpy.types.Panel):
    bl_label = "Legs"
    bl_parent_id = "KODAWARI_PT_gait"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        self.layout.label(text="Joint ranges from the rest pose; positive swings the tip backward")


def _leg(settings, name):
    for leg in settings.legs:
        if leg.name == name:
            return leg
    return None


def _leg_panel(name):
    """One closed sub-panel per leg: each bone's hinge range and stiffness."""

    class Leg(_GaitPanel, bpy.types.Panel):
        bl_label = LEG_LABELS[name]
        bl_parent_id = "KODAWARI_PT_gait_legs"
        bl_options = {"DEFAULT_CLOSED"}

        @classmethod
        def poll(cls, context):
            return (
                in_use.gait(context.object) and _leg(context.object.kodawari_gait, name) is not None
            )

        def draw(self, context):
            layout = in_use.split_layout(self.layout)
            for bone in _leg(context.object.kodawari_gait, name).bones:
                col = layout.column(align=True)
                col.label(text=bone.name, icon="BONE_DATA", translate=False)
                col.prop(bone, "limit_min")
                col.prop(bone, "limit_max")
                col.prop(bone, "stiffness", slider=True)

    Leg.__name__ = Leg.bl_idname = f"KODAWARI_PT_gait_leg_{name.lower()}"
    return Leg


GAIT_ROW_PANELS = tuple(_gait_row_panel(identifier) for identifier, _, _ in GAIT_ITEMS[1:])
LEG_PANELS = tuple(_leg_panel(name) for name in LEG_NAMES)

# Parents before children.
KODAWARI_PT_gait_add = in_use.add_panel(
    "KODAWARI_PT_gait_add",
    "Kodawari Gait",
    "object",
    in_use.can_rig,
    in_use.gait,
    "kodawari.gait_setup",
    "Set Up Gait (find legs)",
    "ANIM",
)


CLASSES = (
    KODAWARI_PT_gait_add,
    KODAWARI_PT_gait,
    KODAWARI_PT_gait_rig,
    KODAWARI_PT_gait_table,
    *GAIT_ROW_PANELS,
    KODAWARI_PT_gait_legs,
    *LEG_PANELS,
)
