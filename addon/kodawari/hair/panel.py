"""The Kodawari Hair panel (Object Data properties of an armature)."""

import bpy

from .. import problems
from . import runtime


class KODAWARI_UL_hair_rods(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        layout.label(text=item.root_bone or "(no bone)", icon="BONE_DATA")
        layout.label(text=f"{len(item.keys)} keys")


class KODAWARI_UL_hair_keys(bpy.types.UIList):
    """Keys with their live weight for the current camera."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        row = layout.row(align=True)
        row.prop(item, "name", text="", emboss=False, icon={"VIEW": "CAMERA_DATA", "POSE": "ARMATURE_DATA",
                                                             "SPEED": "FORCE_WIND"}[item.condition])
        obj = data.id_data
        rt = runtime.get(obj, build=False)
        weight = None
        if rt is not None:
            rod_index = list(obj.kodawari_hair.rods).index(data) if data in list(obj.kodawari_hair.rods) else -1
            weights = rt.weights(rod_index)
            if weights is not None and index + 1 < len(weights):
                weight = weights[index + 1]
        row.label(text="–" if weight is None else f"{weight:.2f}")


class KODAWARI_PT_hair(bpy.types.Panel):
    bl_label = "Kodawari Hair"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return context.object is not None and context.object.type == "ARMATURE"

    def draw_header(self, context):
        self.layout.prop(context.object.kodawari_hair, "enabled", text="")

    def draw(self, context):
        layout = self.layout
        obj = context.object
        settings = obj.kodawari_hair
        rt = runtime.get(obj, build=False)
        problem = (rt.error or rt.status) if rt is not None else ""
        problem = problem or problems.message(obj, "hair")
        if problem:
            layout.label(text=problem, icon="ERROR")
        row = layout.row()
        row.template_list("KODAWARI_UL_hair_rods", "", settings, "rods", settings, "active_rod", rows=3)
        col = row.column(align=True)
        col.operator("kodawari.rod_add", icon="ADD", text="")
        col.operator("kodawari.rod_remove", icon="REMOVE", text="")
        if settings.rods and settings.active_rod < len(settings.rods):
            rod = settings.rods[settings.active_rod]
            box = layout.box()
            box.prop_search(rod, "reference_bone", obj.data, "bones")
            grid = box.grid_flow(columns=2, align=True)
            for name in ("stiffness", "damping", "gravity", "radius", "substeps", "iterations"):
                grid.prop(rod, name)
            box.prop(rod, "wind")
            layout.label(text="Keys (live weight)")
            row = layout.row()
            row.template_list("KODAWARI_UL_hair_keys", "", rod, "keys", rod, "active_key", rows=3)
            col = row.column(align=True)
            col.operator("kodawari.rod_key_remove", icon="REMOVE", text="")
            row = layout.row(align=True)
            row.operator("kodawari.rod_key_view", text="Key View").source = "CAMERA"
            row.operator("kodawari.rod_key_pose", text="Key Pose")
            row.operator("kodawari.rod_key_speed", text="Key Speed")
            row = layout.row(align=True)
            row.operator("kodawari.rod_key_preview", text="Preview")
            row.operator("kodawari.rod_rekey", text="Re-key")
            row.operator("kodawari.rod_fit_stroke", text="Fit Stroke")
            if rod.keys and rod.active_key < len(rod.keys):
                key = rod.keys[rod.active_key]
                sub = layout.column(align=True)
                sub.prop(key, "condition")
                sub.prop(key, "influence")
                if key.condition == "VIEW":
                    sub.prop(key, "direction", text="")
                elif key.condition == "SPEED":
                    sub.prop(key, "speed")
        layout.label(text="Colliders")
        row = layout.row()
        row.template_list("UI_UL_list", "kodawari_colliders", settings, "colliders", settings, "active_collider",
                          rows=2)
        col = row.column(align=True)
        col.operator("kodawari.rod_collider_add", icon="ADD", text="")
        col.operator("kodawari.rod_collider_remove", icon="REMOVE", text="")
        if settings.colliders and settings.active_collider < len(settings.colliders):
            c = settings.colliders[settings.active_collider]
            box = layout.box()
            box.prop_search(c, "bone", obj.data, "bones")
            box.prop(c, "shape")
            box.prop(c, "radius")
            if c.shape == "CAPSULE":
                box.prop(c, "length")
            box.prop(c, "offset")
        layout.operator("kodawari.rod_bake", icon="REC")


CLASSES = (KODAWARI_UL_hair_rods, KODAWARI_UL_hair_keys, KODAWARI_PT_hair)
