"""Operators: gait_setup (find the legs), gait_bake (plan + solve + write an Action),
gait_report (measure the baked Action, write PNG + JSON)."""

import bpy
import numpy as np

from .. import editable, native
from ..bake_job import BakeError, BakeOperator, frame_range
from . import rig as rigmod
from .bake import GaitBakeJob
from .props import LEG_NAMES
from .report import write_report


def _armature(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "ARMATURE" else None


class KODAWARI_OT_gait_setup(bpy.types.Operator):
    """Find the four legs (by name, or from four selected feet) and the body bone, and fill in horse settings"""

    bl_idname = "kodawari.gait_setup"
    bl_label = "Gait Setup"
    bl_options = {"REGISTER", "UNDO"}

    def execute(self, context):
        obj = _armature(context)
        if obj is None:
            self.report({"ERROR"}, "Gait Setup needs an armature as the active object")
            return {"CANCELLED"}
        why = editable.why_not(obj, "get a gait")
        if why:
            self.report({"ERROR"}, why)
            return {"CANCELLED"}
        armature = obj.data
        selected = [pb.name for pb in (context.selected_pose_bones or [])] if context.mode == "POSE" else []
        if len(selected) == 4:
            legs, how = rigmod.find_legs_from_feet(armature, selected), "from the four selected feet"
        else:
            legs, how = rigmod.find_legs_by_name(armature), "by name"
        missing = [k for k in LEG_NAMES if k not in legs]
        if missing:
            found = ", ".join(f"{k} ({len(v)} bones)" for k, v in legs.items()) or "none"
            self.report({"ERROR"}, f"Found fewer than four legs {how}: found {found}; missing {', '.join(missing)}. "
                        "Name leg bones with a side (.L/.R, _L/_R, Left/Right) and an end (fore/front/arm, "
                        "hind/back/rear), or select the four foot bones in Pose Mode")
            return {"CANCELLED"}
        short = [k for k in LEG_NAMES if len(legs[k]) < 2]
        if short:
            self.report({"ERROR"}, f"Leg {', '.join(short)} has a single bone; a leg needs 2 to 6 bones")
            return {"CANCELLED"}
        body = rigmod.find_body(armature, legs)
        if body is None:
            self.report({"ERROR"}, "No body bone: the four legs need a common parent bone to carry root motion")
            return {"CANCELLED"}
        # Validate the geometry before touching the settings.
        probe = {"forward": rigmod.forward_of(armature, legs), "body_head": np.zeros(3), "body_rest": np.eye(3),
                 "legs": []}
        for k in LEG_NAMES:
            bones = [armature.bones[n] for n in legs[k]]
            probe["legs"].append({"heads": np.array([b.head_local for b in bones], dtype=np.float64),
                                  "tail": np.array(bones[-1].tail_local, dtype=np.float64),
                                  "limit_min": np.full(len(bones), -1.0), "limit_max": np.full(len(bones), 1.0),
                                  "stiffness": np.ones(len(bones))})
        why = native.module().gait_validate_rig(probe)
        if why:
            self.report({"ERROR"}, f"The legs cannot be solved: {why}")
            return {"CANCELLED"}
        rigmod.fill_horse_defaults(obj.kodawari_gait, armature, legs, body)
        summary = "; ".join(f"{k}: {' > '.join(legs[k])}" for k in LEG_NAMES)
        self.report({"INFO"}, f"Found 4 legs {how} and body bone '{body}'. {summary}")
        return {"FINISHED"}


class KODAWARI_OT_gait_bake(BakeOperator, bpy.types.Operator):
    """Plan the gait from the speed curve, solve every leg, and bake it to an Action"""

    bl_idname = "kodawari.gait_bake"
    bl_label = "Bake Gait"
    bl_options = {"REGISTER", "UNDO"}

    def make_job(self, context):
        obj = _armature(context) or context.active_object
        why = editable.why_not(obj, "bake a gait")
        if why:
            raise BakeError(why)
        start, end = frame_range(self, context.scene)
        try:
            return GaitBakeJob(context, obj, start, end)
        except ValueError as exc:
            raise BakeError(f"Gait bake: {exc}") from None


class KODAWARI_OT_gait_report(bpy.types.Operator):
    """Measure the baked gait: footfalls and foot paths (picture) and how smooth each stretch is (JSON)"""

    bl_idname = "kodawari.gait_report"
    bl_label = "Gait Report"
    bl_options = {"REGISTER", "UNDO"}

    filepath: bpy.props.StringProperty(name="File Path", subtype="FILE_PATH", default="//gait_report.png",
                                        description="Where to write the report")

    def execute(self, context):
        obj = _armature(context)
        if obj is None:
            self.report({"ERROR"}, "Gait Report needs an armature as the active object")
            return {"CANCELLED"}
        if not self.filepath:
            self.report({"ERROR"}, "Gait Report needs a file path")
            return {"CANCELLED"}
        scene = context.scene
        try:
            png, js, _ = write_report(obj, self.filepath, scene.render.fps / scene.render.fps_base)
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, f"Gait report: {exc}")
            return {"CANCELLED"}
        self.report({"INFO"}, f"Wrote {png} and {js}")
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}
