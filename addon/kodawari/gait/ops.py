"""Operators: gait_setup (find the legs), gait_bake (plan + solve + write an Action),
gait_report (measure the baked Action, write PNG + JSON)."""

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_

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
    """Find the four legs (by name, or from four selected feet) and the bone that carries the animal; fill in a horse's gaits scaled to this animal and joint ranges from its rest pose"""

    bl_idname = "kodawari.gait_setup"
    bl_label = "Gait Setup"
    bl_options = {"REGISTER", "UNDO"}

    limits: bpy.props.EnumProperty(
        name="Joint Ranges",
        default="REST",
        description="How far each leg joint may bend",
        items=(
            (
                "REST",
                "From Rest Pose",
                "Each joint bends the way it bends at rest, within a range around it",
            ),
            (
                "HORSE",
                "Horse",
                "A horse's joint ranges for 4-bone legs (other legs: from the rest pose)",
            ),
        ),
    )
    root_motion: bpy.props.EnumProperty(
        name="Root Motion",
        default="AUTO",
        description="Where the bake keys the animal's travel",
        items=(
            (
                "AUTO",
                "Automatic",
                "The body bone when the legs share one, else the armature object",
            ),
            (
                "BONE",
                "Body Bone",
                "The topmost bone carrying the legs whose location Blender applies",
            ),
            ("OBJECT", "Armature Object", "The armature object itself"),
        ),
    )

    def execute(self, context):
        obj = _armature(context)
        if obj is None:
            self.report({"ERROR"}, tip_("Gait Setup needs an armature as the active object"))
            return {"CANCELLED"}
        why = editable.why_not(obj, tip_("get a gait"))
        if why:
            self.report({"ERROR"}, why)
            return {"CANCELLED"}
        try:
            why = self._setup(context, obj)
        except ValueError as exc:
            why = str(exc)
        if why:
            self.report({"ERROR"}, why)
            return {"CANCELLED"}
        return {"FINISHED"}

    def _setup(self, context, obj):
        """Everything is checked before anything is written: returns why not, or None."""
        armature = obj.data
        selected = (
            [pb.name for pb in (context.selected_pose_bones or [])]
            if context.mode == "POSE"
            else []
        )
        if len(selected) == 4:
            rigmod.gait_frame(obj)
            legs, how = (
                rigmod.find_legs_from_feet(armature, selected),
                tip_("from the four selected feet"),
            )
        else:
            legs, how = rigmod.find_legs_by_name(armature), tip_("by name")
        legs = rigmod.with_shoulders(armature, legs)
        missing = [k for k in LEG_NAMES if k not in legs]
        if missing:
            found = ", ".join(f"{k} ({len(v)} bones)" for k, v in legs.items()) or "none"
            return tip_(
                "Found fewer than four legs {}: found {}; missing {}. Name leg bones with a side (.L/.R, _l/_r, Left/Right, 'L ') and a limb (thigh, shin, foot, upper_arm, forearm, hand, or fore/hind), or select the four foot bones in Pose Mode"
            ).format(how, found, ", ".join(missing))
        for k in LEG_NAMES:
            if len(legs[k]) < 2:
                return tip_(
                    "Leg {} ('{}') has a single bone; a leg needs 2 to 6 bones (a bone from the body to the foot cannot bend)"
                ).format(k, legs[k][0])
            if len(legs[k]) > 6:
                return tip_("Leg {} has {} bones ({}); a leg needs 2 to 6").format(
                    k, len(legs[k]), " > ".join(legs[k])
                )
        body = rigmod.find_body(armature, legs)
        root_motion = self.root_motion
        if root_motion == "AUTO":
            root_motion = "BONE" if body is not None else "OBJECT"
        if root_motion == "BONE" and body is None:
            return tip_(
                "No body bone: the four legs have no common parent bone to carry root motion (use Root Motion: Armature Object)"
            )
        # Validate the geometry before touching the settings.
        forward = rigmod.forward_of(obj, legs)
        probe = {"forward": forward, "body_head": np.zeros(3), "body_rest": np.eye(3), "legs": []}
        ground = min(float(rigmod.leg_points(obj, legs[k])[1][2]) for k in LEG_NAMES)
        for k in LEG_NAMES:
            heads, tail = rigmod.leg_points(obj, legs[k])
            probe["legs"].append(
                {
                    "heads": heads,
                    "tail": tail,
                    "limit_min": np.full(len(heads), -1.0),
                    "limit_max": np.full(len(heads), 1.0),
                    "stiffness": np.ones(len(heads)),
                }
            )
            d = np.diff(np.vstack([heads, tail[None, :]]), axis=0)
            planar = float(np.hypot(d @ forward, d[:, 2]).sum())
            drop = float(heads[0][2]) - ground
            if drop > planar * 0.999:
                return (
                    f"Leg {k} cannot reach the ground: its root '{legs[k][0]}' is {drop:.3g} m above the "
                    f"lowest foot but the leg is only {planar:.3g} m long"
                )
        why = native.module().gait_validate_rig(probe)
        if why:
            return tip_("The legs cannot be solved: {}").format(why)
        rigmod.fill_defaults(
            obj.kodawari_gait, obj, legs, body, preset=self.limits, root_motion=root_motion
        )
        summary = "; ".join(f"{k}: {' > '.join(legs[k])}" for k in LEG_NAMES)
        where = (
            tip_("body bone '{}'").format(body)
            if root_motion == "BONE"
            else tip_("the armature object")
        )
        self.report(
            {"INFO"}, tip_("Found 4 legs {}; root motion on {}. {}").format(how, where, summary)
        )
        return None


class KODAWARI_OT_gait_bake(BakeOperator, bpy.types.Operator):
    """Plan the gait from the speed curve, solve every leg, and bake it to an Action"""

    bl_idname = "kodawari.gait_bake"
    bl_label = "Bake Gait"
    bl_options = {"REGISTER", "UNDO"}

    def make_job(self, context):
        obj = _armature(context) or context.active_object
        why = editable.why_not(obj, tip_("bake a gait"))
        if why:
            raise BakeError(why)
        start, end = frame_range(self, context.scene)
        try:
            return GaitBakeJob(context, obj, start, end)
        except ValueError as exc:
            raise BakeError(tip_("Gait bake: {}").format(exc)) from None


class KODAWARI_OT_gait_report(bpy.types.Operator):
    """Measure the baked gait: footfalls and foot paths (picture) and how smooth each stretch is (JSON)"""

    bl_idname = "kodawari.gait_report"
    bl_label = "Gait Report"
    bl_options = {"REGISTER", "UNDO"}

    filepath: bpy.props.StringProperty(
        name="File Path",
        subtype="FILE_PATH",
        default="//gait_report.png",
        description="Where to write the report",
    )

    def execute(self, context):
        obj = _armature(context)
        if obj is None:
            self.report({"ERROR"}, tip_("Gait Report needs an armature as the active object"))
            return {"CANCELLED"}
        if not self.filepath:
            self.report({"ERROR"}, tip_("Gait Report needs a file path"))
            return {"CANCELLED"}
        scene = context.scene
        try:
            png, js, _ = write_report(obj, self.filepath, scene.render.fps / scene.render.fps_base)
        except (ValueError, OSError) as exc:
            self.report({"ERROR"}, tip_("Gait report: {}").format(exc))
            return {"CANCELLED"}
        self.report({"INFO"}, tip_("Wrote {} and {}").format(png, js))
        return {"FINISHED"}

    def invoke(self, context, event):
        context.window_manager.fileselect_add(self)
        return {"RUNNING_MODAL"}
