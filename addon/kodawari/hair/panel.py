"""The Kodawari Hair panel (Object Data properties of an armature with rods), in
Blender's layout: the rod list on top, the active rod's settings, its keys and the
colliders in sub-panels, the solver quality closed by default."""

import bpy
from bpy.app.translations import pgettext_iface as iface_

from .. import in_use, problems
from . import runtime

CONDITION_ICONS = {"VIEW": "CAMERA_DATA", "POSE": "ARMATURE_DATA", "SPEED": "FORCE_WIND"}


def _count(n, one, many):
    return iface_(one) if n == 1 else iface_(many).format(n)


class KODAWARI_UL_hair_rods(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        row = layout.row()
        row.label(text=item.root_bone or iface_("(no bone)"), icon="BONE_DATA", translate=False)
        row.label(text=_count(len(item.keys), "1 key", "{} keys"), translate=False)


class KODAWARI_UL_hair_keys(bpy.types.UIList):
    """Keys with their live weight for the current camera."""

    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        row = layout.row(align=True)
        row.prop(item, "name", text="", emboss=False, icon=CONDITION_ICONS[item.condition])
        obj = data.id_data
        rt = runtime.get(obj, build=False)
        weight = None
        if rt is not None:
            rods = list(obj.kodawari_hair.rods)
            rod_index = rods.index(data) if data in rods else -1
            weights = rt.weights(rod_index)
            if weights is not None and index + 1 < len(weights):
                weight = weights[index + 1]
        row.label(text="–" if weight is None else f"{weight:.2f}", translate=False)


class KODAWARI_UL_hair_colliders(bpy.types.UIList):
    def draw_item(self, context, layout, data, item, icon, active_data, active_propname, index=0):
        row = layout.row()
        shape_icon = "MESH_UVSPHERE" if item.shape == "SPHERE" else "MESH_CAPSULE"
        row.label(text=item.bone or iface_("(no bone)"), icon=shape_icon, translate=False)
        row.prop(item, "shape", text="", emboss=False)


def _active_rod(settings):
    if settings.rods and 0 <= settings.active_rod < len(settings.rods):
        return settings.rods[settings.active_rod]
    return None


class _HairPanel:
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "data"

    @classmethod
    def poll(cls, context):
        return in_use.hair(context.object)


class KODAWARI_PT_hair(_HairPanel, bpy.types.Panel):
    bl_label = "Kodawari Hair"

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
            layout.label(text=problem, icon="ERROR", translate=False)
        layout.template_list(
            "KODAWARI_UL_hair_rods", "", settings, "rods", settings, "active_rod", rows=3
        )
        row = layout.row(align=True)
        row.operator("kodawari.rod_add", text="Add Rod", icon="ADD")
        row.operator("kodawari.rod_remove", text="Remove Rod", icon="REMOVE")
        layout.operator("kodawari.rod_bake", icon="REC")


class KODAWARI_PT_hair_rod(_HairPanel, bpy.types.Panel):
    bl_label = "Rod"
    bl_parent_id = "KODAWARI_PT_hair"

    @classmethod
    def poll(cls, context):
        return in_use.hair(context.object) and _active_rod(context.object.kodawari_hair) is not None

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        obj = context.object
        rod = _active_rod(obj.kodawari_hair)
        col = layout.column()
        col.prop_search(rod, "reference_bone", obj.data, "bones", text="Reference")
        col = layout.column()
        col.prop(rod, "stiffness", slider=True)
        col.prop(rod, "damping")
        col.prop(rod, "gravity")
        layout.column().prop(rod, "wind")


class KODAWARI_PT_hair_rod_quality(_HairPanel, bpy.types.Panel):
    bl_label = "Collision and Quality"
    bl_parent_id = "KODAWARI_PT_hair_rod"
    bl_options = {"DEFAULT_CLOSED"}

    @classmethod
    def poll(cls, context):
        return KODAWARI_PT_hair_rod.poll(context)

    def draw(self, context):
        layout = in_use.split_layout(self.layout)
        rod = _active_rod(context.object.kodawari_hair)
        col = layout.column()
        col.prop(rod, "radius")
        col.prop(rod, "substeps")
        col.prop(rod, "iterations")


class KODAWARI_PT_hair_keys(_HairPanel, bpy.types.Panel):
    bl_label = "Keys"
    bl_parent_id = "KODAWARI_PT_hair"

    @classmethod
    def poll(cls, context):
        return KODAWARI_PT_hair_rod.poll(context)

    def draw(self, context):
        layout = self.layout
        rod = _active_rod(context.object.kodawari_hair)
        row = layout.row()
        row.template_list("KODAWARI_UL_hair_keys", "", rod, "keys", rod, "active_key", rows=3)
        col = row.column(align=True)
        col.menu("KODAWARI_MT_hair_key_add", icon="ADD", text="")
        col.operator("kodawari.rod_key_remove", icon="REMOVE", text="")
        row = layout.row(align=True)
        row.operator("kodawari.rod_key_preview", text="Preview", icon="HIDE_OFF")
        row.operator("kodawari.rod_rekey", text="Re-key", icon="FILE_REFRESH")
        layout.operator("kodawari.rod_fit_stroke", icon="GREASEPENCIL")
        if rod.keys and 0 <= rod.active_key < len(rod.keys):
            key = rod.keys[rod.active_key]
            col = in_use.split_layout(layout.column())
            col.prop(key, "condition")
            col.prop(key, "influence")
            if key.condition == "VIEW":
                col.prop(key, "direction", text="Direction")
            elif key.condition == "SPEED":
                col.prop(key, "speed")


class KODAWARI_PT_hair_colliders(_HairPanel, bpy.types.Panel):
    bl_label = "Colliders"
    bl_parent_id = "KODAWARI_PT_hair"
    bl_options = {"DEFAULT_CLOSED"}

    def draw(self, context):
        layout = self.layout
        obj = context.object
        settings = obj.kodawari_hair
        row = layout.row()
        row.template_list(
            "KODAWARI_UL_hair_colliders",
            "",
            settings,
            "colliders",
            settings,
            "active_collider",
            rows=2,
        )
        col = row.column(align=True)
        col.operator("kodawari.rod_collider_add", icon="ADD", text="")
        col.operator("kodawari.rod_collider_remove", icon="REMOVE", text="")
        if settings.colliders and 0 <= settings.active_collider < len(settings.colliders):
            collider = settings.colliders[settings.active_collider]
            col = in_use.split_layout(layout.column())
            col.prop_search(collider, "bone", obj.data, "bones")
            col.prop(collider, "shape")
            col.prop(collider, "radius")
            if collider.shape == "CAPSULE":
                col.prop(collider, "length")
            col.prop(collider, "offset")


KODAWARI_PT_hair_add = in_use.add_panel(
    "KODAWARI_PT_hair_add",
    "Kodawari Hair",
    "data",
    in_use.can_rig,
    in_use.hair,
    "kodawari.rod_add",
    "Add Hair Rod (selected bones)",
    "STRANDS",
)


CLASSES = (
    KODAWARI_UL_hair_rods,
    KODAWARI_UL_hair_keys,
    KODAWARI_UL_hair_colliders,
    KODAWARI_PT_hair_add,
    KODAWARI_PT_hair,
    KODAWARI_PT_hair_rod,
    KODAWARI_PT_hair_rod_quality,
    KODAWARI_PT_hair_keys,
    KODAWARI_PT_hair_colliders,
)
