"""The Fish Swim panel in the Modifier Properties tab (our deformer's "modifier")."""

import bpy

from .. import problems
from . import overlay, runtime


class KODAWARI_UL_swim_fins(bpy.types.UIList):
    bl_idname = "KODAWARI_UL_swim_fins"

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index):
        row = layout.row(align=True)
        row.prop(item, "enabled", text="")
        row.label(text=item.vertex_group or "(no group)")
        row.label(text=f"{item.kind.title()} · {item.motion.replace('_', '-').title()}")


class KODAWARI_PT_swim(bpy.types.Panel):
    bl_idname = "KODAWARI_PT_swim"
    bl_label = "Fish Swim (Kodawari)"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "modifier"

    # The axis overlay lives as long as the panel is registered.
    @classmethod
    def register(cls):
        overlay.add()

    @classmethod
    def unregister(cls):
        overlay.remove()

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "MESH"

    def draw_header(self, context):
        settings = context.object.kodawari_swim
        if runtime.swim_key_block(context.object) is not None:
            self.layout.prop(settings, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        obj = context.object
        settings = obj.kodawari_swim
        if runtime.swim_key_block(obj) is None and settings.baked == "NONE":
            layout.operator("kodawari.swim_add", icon="MOD_WAVE")
            return
        if settings.baked != "NONE":
            layout.label(
                text=f"Baked to {settings.baked.replace('_', ' ').title()}"
                + (f": {settings.cache_path}" if settings.baked == "MESH_CACHE" else ""),
                icon="CHECKMARK",
            )
            layout.operator("kodawari.swim_free_bake", icon="TRASH")
            layout.operator("kodawari.swim_remove", icon="X")
            return
        problem = problems.message(obj, "swim")
        if problem:
            box = layout.box()
            box.alert = True
            box.label(text=f"Not swimming: {problem}", icon="ERROR")
        layout.prop(settings, "preset")
        row = layout.row(align=True)
        row.prop(settings, "head_axis")
        row.operator("kodawari.swim_flip_head", text="", icon="ARROW_LEFTRIGHT")
        if settings.head_guess:
            layout.label(text=settings.head_guess, icon="INFO")
        col = layout.column(align=True)
        col.prop(settings, "frequency")
        col.prop(settings, "wavelength")
        col.prop(settings, "amplitude")
        col.prop(settings, "amplitude_head")
        col.prop(settings, "envelope_start")
        col.prop(settings, "envelope_power")
        col.prop(settings, "phase_offset")
        layout.prop(settings, "bend", expand=True)
        row = layout.row()
        row.prop(settings, "preserve_length")
        row.prop(settings, "control_points")
        layout.prop(settings, "show_axis")
        row = layout.row(align=True)
        row.prop(settings, "speed_mode")
        if settings.speed_mode == "STROUHAL":
            row.prop(settings, "strouhal")
        if settings.speed_mode != "NONE" and any(c.type == "FOLLOW_PATH" for c in obj.constraints):
            layout.prop(settings, "path_start")

        layout.label(text="Fins")
        row = layout.row()
        row.template_list(
            "KODAWARI_UL_swim_fins", "", settings, "fins", settings, "fin_index", rows=3
        )
        col = row.column(align=True)
        col.operator("kodawari.swim_fin_add", text="", icon="ADD")
        col.operator("kodawari.swim_fin_remove", text="", icon="REMOVE")
        col.operator("kodawari.swim_fin_find", text="", icon="VIEWZOOM")
        if 0 <= settings.fin_index < len(settings.fins):
            fin = settings.fins[settings.fin_index]
            box = layout.box()
            box.prop_search(fin, "vertex_group", obj, "vertex_groups")
            box.prop(fin, "kind")
            box.prop(fin, "motion")
            col = box.column(align=True)
            col.prop(fin, "amplitude")
            col.prop(fin, "frequency_ratio")
            col.prop(fin, "phase_lag")
            if fin.motion == "FLAP":
                col.prop(fin, "feathering")
            if fin.motion == "UNDULATE":
                col.prop(fin, "wavelength")
            col.prop(fin, "root_blend")

        layout.separator()
        row = layout.row(align=True)
        op = row.operator("kodawari.swim_bake", text="Bake to Mesh Cache", icon="FILE_CACHE")
        op.target = "MESH_CACHE"
        op = row.operator("kodawari.swim_bake", text="Bake to Shape Keys", icon="SHAPEKEY_DATA")
        op.target = "SHAPE_KEYS"
        layout.operator("kodawari.swim_remove", icon="X")
