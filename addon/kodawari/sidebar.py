"""The "Kodawari" tab of the 3D View sidebar (N): the active object's creature at a glance,
its main settings and bakes, or the "Add …" entry for what it could become."""

import bpy

from . import in_use


class KODAWARI_PT_sidebar(bpy.types.Panel):
    bl_idname = "KODAWARI_PT_sidebar"
    bl_label = "Creature"
    bl_space_type = "VIEW_3D"
    bl_region_type = "UI"
    bl_category = "Kodawari"

    @classmethod
    def poll(cls, context):
        return context.object is not None

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        obj = context.object
        layout.label(text=obj.name, icon="OBJECT_DATA")
        if not (in_use.can_swim(obj) or in_use.can_rig(obj)):
            layout.label(text="Kodawari works on fish meshes and armatures", icon="INFO")
            return
        if in_use.swim(obj):
            _draw_swim(layout, obj)
        elif in_use.can_swim(obj):
            layout.operator("kodawari.swim_add", icon="MOD_WAVE")
        if in_use.can_rig(obj):
            if in_use.hair(obj):
                _draw_hair(layout, obj)
            else:
                layout.operator("kodawari.rod_add", text="Add Hair Rod", icon="STRANDS")
            if in_use.gait(obj):
                _draw_gait(layout, obj)
            else:
                layout.operator("kodawari.gait_setup", icon="ANIM")


def _heading(layout, text, icon):
    col = layout.column()
    col.separator()
    col.label(text=text, icon=icon)
    return col


def _draw_swim(layout, obj):
    settings = obj.kodawari_swim
    col = _heading(layout, "Fish Swim", "MOD_WAVE")
    if settings.baked != "NONE":
        col.label(text="Baked", icon="CHECKMARK")
        return
    col.prop(settings, "enabled", text="Show in Viewport")
    col.prop(settings, "preset")
    col.prop(settings, "frequency")
    col.prop(settings, "amplitude", slider=True)
    col.operator("kodawari.swim_bake", text="Bake", icon="FILE_CACHE").target = "MESH_CACHE"


def _draw_hair(layout, obj):
    settings = obj.kodawari_hair
    col = _heading(layout, "Hair", "STRANDS")
    col.prop(settings, "enabled", text="Live Simulation")
    col.label(text=_count(len(settings.rods), "1 rod", "{} rods"), translate=False)
    col.operator("kodawari.rod_bake", text="Bake", icon="REC")


def _draw_gait(layout, obj):
    settings = obj.kodawari_gait
    col = _heading(layout, "Gait", "ANIM")
    col.prop(settings, "speed")
    col.prop(settings, "gait")
    row = col.row(align=True)
    row.operator("kodawari.gait_bake", text="Bake", icon="REC")
    row.operator("kodawari.gait_report", text="Report", icon="GRAPH")


def _count(n, one, many):
    from bpy.app.translations import pgettext_iface as iface_

    return iface_(one) if n == 1 else iface_(many).format(n)


CLASSES = (KODAWARI_PT_sidebar,)
