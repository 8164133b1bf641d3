"""The Fish Swim panel in the Modifier tab, laid out like a modifier: eye and camera
toggles in the header, where it runs in the stack, the everyday settings on top,
the rest in sub-panels (body wave and travel start closed)."""

import bpy
from bpy.app.translations import pgettext_iface as iface_

from .. import in_use, problems
from . import overlay, route, visibility

MODIFIER_ICONS = {
    "ARMATURE": "MOD_ARMATURE",
    "SUBSURF": "MOD_SUBSURF",
    "MIRROR": "MOD_MIRROR",
    "MESH_CACHE": "MOD_MESHDEFORM",
    "SOLIDIFY": "MOD_SOLIDIFY",
    "BEVEL": "MOD_BEVEL",
    "NODES": "GEOMETRY_NODES",
}


class KODAWARI_UL_swim_fins(bpy.types.UIList):
    bl_idname = "KODAWARI_UL_swim_fins"

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "enabled", text="")
        split = row.split(factor=0.6)
        split.label(text=item.vertex_group or iface_("(no group)"), translate=False)
        split.prop(item, "kind", text="", emboss=False)


def _live(context):
    obj = context.object
    return in_use.swim(obj) and obj.kodawari_swim.baked == "NONE"


def wrap(text, width=30):
    """Lines of at most `width` characters, so a long note is not cut off at the default width."""
    lines, line = [], ""
    for word in text.split():
        if line and len(line) + 1 + len(word) > width:
            lines.append(line)
            line = word
        else:
            line = f"{line} {word}".strip()
    return [*lines, line] if line else lines


class _SwimPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "modifier"

    @classmethod
    def poll(cls, context):
        return _live(context)


class KODAWARI_PT_swim(_SwimPanel, bpy.types.Panel):
    bl_idname = "KODAWARI_PT_swim"
    bl_label = "Fish Swim"
    bl_order = 0  # above the modifier stack: the swim runs before every modifier

    # The axis overlay lives as long as the panel is registered.
    @classmethod
    def register(cls):
        overlay.add()

    @classmethod
    def unregister(cls):
        overlay.remove()

    @classmethod
    def poll(cls, context):
        return in_use.swim(context.object)

    def draw_header(self, context):
        settings = context.object.kodawari_swim
        if settings.baked == "NONE":
            visibility.draw_toggles(self.layout, settings)

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        obj = context.object
        settings = obj.kodawari_swim
        if settings.baked != "NONE":
            col = layout.column()
            target = settings.bl_rna.properties["baked"].enum_items[settings.baked].name
            col.label(
                text=iface_("Baked to {}").format(iface_(target)), icon="CHECKMARK", translate=False
            )
            if settings.baked == "MESH_CACHE":
                col.label(text=settings.cache_path, icon="FILE_CACHE", translate=False)
            col = layout.column(align=True)  # stacked: side by side, "Remove Fish Swim" is cut off
            col.operator("kodawari.swim_free_bake", icon="TRASH")
            col.operator("kodawari.swim_remove", icon="X")
            return
        problem = problems.message(obj, "swim")
        if problem:
            box = layout.box()
            box.alert = True
            box.label(
                text=iface_("Not swimming: {}").format(problem), icon="ERROR", translate=False
            )
        layout.label(text="Runs before all modifiers", icon="SORT_ASC")
        col = layout.column()
        col.prop(settings, "preset")
        row = col.row(align=True)
        row.prop(settings, "head_axis")
        row.operator("kodawari.swim_flip_head", text="", icon="ARROW_LEFTRIGHT")
        if settings.head_guess:
            note = layout.column(align=True)
            for index, line in enumerate(wrap(settings.head_guess)):
                note.label(text=line, icon="INFO" if index == 0 else "BLANK1", translate=False)
        col = layout.column()
        col.prop(settings, "frequency")
        col.prop(settings, "amplitude", slider=True)
        col.prop(settings, "wavelength")
        col.prop(settings, "bend")
        layout.separator()
        col = layout.column(align=True)
        col.operator(
            "kodawari.swim_bake", text="Bake to Mesh Cache", icon="FILE_CACHE"
        ).target = "MESH_CACHE"
        col.operator(
            "kodawari.swim_bake", text="Bake to Shape Keys", icon="SHAPEKEY_DATA"
        ).target = "SHAPE_KEYS"
        row = layout.row(align=True)
        row.operator("kodawari.swim_apply", text="Apply", icon="CHECKMARK")
        row.operator("kodawari.swim_remove", text="Remove", icon="X")


class KODAWARI_PT_swim_body(_SwimPanel, bpy.types.Panel):
    bl_label = "Body Wave"
    bl_parent_id = "KODAWARI_PT_swim"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        settings = context.object.kodawari_swim
        col = layout.column()
        col.prop(settings, "amplitude_head", slider=True)
        col.prop(settings, "envelope_start", slider=True)
        col.prop(settings, "envelope_power")
        col.prop(settings, "phase_offset")
        col = layout.column()
        col.prop(settings, "preserve_length")
        col.prop(settings, "control_points")
        col.prop(settings, "show_axis")


class KODAWARI_PT_swim_travel(_SwimPanel, bpy.types.Panel):
    bl_label = "Travel"
    bl_parent_id = "KODAWARI_PT_swim"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        obj = context.object
        settings = obj.kodawari_swim
        col = layout.column()
        col.prop(settings, "speed_mode")
        if settings.speed_mode == "STROUHAL":
            col.prop(settings, "strouhal")
        if settings.speed_mode != "NONE" and any(c.type == "FOLLOW_PATH" for c in obj.constraints):
            col.prop(settings, "path_start", slider=True)


class KODAWARI_PT_swim_fins(_SwimPanel, bpy.types.Panel):
    bl_label = "Fins"
    bl_parent_id = "KODAWARI_PT_swim"

    def draw(self, context):
        layout = self.layout
        obj = context.object
        settings = obj.kodawari_swim
        row = layout.row()
        row.template_list(
            "KODAWARI_UL_swim_fins", "", settings, "fins", settings, "fin_index", rows=3
        )
        col = row.column(align=True)
        col.operator("kodawari.swim_fin_add", text="", icon="ADD")
        col.operator("kodawari.swim_fin_remove", text="", icon="REMOVE")
        col.separator()
        col.operator("kodawari.swim_fin_find", text="", icon="VIEWZOOM")
        if 0 <= settings.fin_index < len(settings.fins):
            fin = settings.fins[settings.fin_index]
            col = in_use.split_layout(layout.column())
            col.prop_search(fin, "vertex_group", obj, "vertex_groups")
            col.prop(fin, "kind")
            col.prop(fin, "motion")
            col = in_use.split_layout(layout.column())
            col.prop(fin, "amplitude")
            col.prop(fin, "frequency_ratio")
            col.prop(fin, "phase_lag")
            if fin.motion == "FLAP":
                col.prop(fin, "feathering")
            if fin.motion == "UNDULATE":
                col.prop(fin, "wavelength")
            col.prop(fin, "root_blend", slider=True)


class KODAWARI_PT_swim_order(_SwimPanel, bpy.types.Panel):
    """Where the swim sits among the object's modifiers (it always runs first)."""

    bl_label = "Evaluation Order"
    bl_parent_id = "KODAWARI_PT_swim"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        col = self.layout.column(align=True)
        obj = context.object
        first = 1
        if route.modifier(obj) is None:  # an older file: the swim is still its shape key
            col.label(text=iface_("1. Fish Swim (shape key)"), icon="MOD_WAVE", translate=False)
            first = 2
        swim = route.modifier(obj)
        for index, modifier in enumerate(obj.modifiers, start=first):
            icon = "MOD_WAVE" if modifier == swim else MODIFIER_ICONS.get(modifier.type, "MODIFIER")
            col.label(text=f"{index}. {modifier.name}", icon=icon, translate=False)


KODAWARI_PT_swim_add = in_use.add_panel(
    "KODAWARI_PT_swim_add",
    "Fish Swim",
    "modifier",
    in_use.can_swim,
    in_use.swim,
    "kodawari.swim_add",
    "Add Fish Swim",
    "MOD_WAVE",
)


CLASSES = (
    KODAWARI_UL_swim_fins,
    KODAWARI_PT_swim_add,
    KODAWARI_PT_swim,
    KODAWARI_PT_swim_body,
    KODAWARI_PT_swim_travel,
    KODAWARI_PT_swim_fins,
    KODAWARI_PT_swim_order,
)
