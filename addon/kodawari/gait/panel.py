"""The gait panel in the armature's Object properties."""

import bpy


class KODAWARI_PT_gait(bpy.types.Panel):
    bl_label = "Kodawari Gait"
    bl_space_type = "PROPERTIES"
    bl_region_type = "WINDOW"
    bl_context = "object"

    @classmethod
    def poll(cls, context):
        return context.active_object is not None and context.active_object.type == "ARMATURE"

    def draw(self, context):
        layout = self.layout
        settings = context.active_object.kodawari_gait
        layout.operator("kodawari.gait_setup")
        col = layout.column()
        col.prop(settings, "speed")
        col.prop(settings, "gait")
        col.prop(settings, "acceleration")
        col.prop(settings, "root_motion")
        col.prop_search(settings, "body_bone", context.active_object.data, "bones")
        col.prop(settings, "ccd_iterations")
        col.prop(settings, "ground")
        col.prop(settings, "path")
        row = layout.row(align=True)
        row.operator("kodawari.gait_bake")
        row.operator("kodawari.gait_report")
        box = layout.box()
        box.label(text="Gait table")
        row = box.row()
        row.prop(settings, "use_froude")
        row.prop(settings, "hysteresis")
        row.prop(settings, "reach")
        for entry in settings.table:
            sub = box.column(align=True)
            sub.label(text=entry.name)
            r = sub.row(align=True)
            r.prop(entry, "duty_factor", text="Duty")
            r.prop(entry, "duty_factor_top", text="Duty Top")
            r.prop(entry, "phase_fore_hind", text="D1")
            r.prop(entry, "phase_left_right", text="D2")
            r.prop(entry, "swing_time", text="Swing")
            r = sub.row(align=True)
            r.prop(entry, "swing_height", text="Lift")
            r.prop(entry, "bob", text="Bob")
            r.prop(entry, "speed_max" if not settings.use_froude else "froude_max", text="Top")
            r.prop(entry, "use_in_auto", text="Auto")
        for leg in settings.legs:
            box = layout.box()
            box.label(text=f"Leg {leg.name}")
            for bone in leg.bones:
                r = box.row(align=True)
                r.label(text=bone.name)
                r.prop(bone, "limit_min")
                r.prop(bone, "limit_max")
                r.prop(bone, "stiffness")
