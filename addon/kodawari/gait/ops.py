"""Operators: gait_setup (find the legs), gait_bake (plan + solve + write an Action),
gait_report (measure the baked Action, write PNG + JSON)."""

import bpy
import numpy as np

from .. import native
from . import rig as rigmod
from .bake import GaitBakeJob
from .props import LEG_NAMES
from .report import write_report


def _armature(context):
    obj = context.active_object
    return obj if obj is not None and obj.type == "ARMATURE" else None


class KODAWARI_OT_gait_setup(bpy.types.Operator):
    """Find the four legs (by name, or from four selected foot bones) and the bone that
    carries root motion; fill the gait settings with the horse's gait table scaled to
    this animal and joint ranges from the rig's rest pose"""

    bl_idname = "kodawari.gait_setup"
    bl_label = "Gait Setup"
    bl_options = {"REGISTER", "UNDO"}

    limits: bpy.props.EnumProperty(
        name="Joint Ranges", default="REST",
        items=(("REST", "From Rest Pose", "Each joint bends the way it bends at rest, within a range around it"),
               ("HORSE", "Horse", "The seed's horse ranges for 4-bone legs (others from the rest pose)")))
    root_motion: bpy.props.EnumProperty(
        name="Root Motion", default="AUTO",
        items=(("AUTO", "Automatic", "The body bone when the legs share one, else the armature object"),
               ("BONE", "Body Bone", "The topmost bone carrying the legs whose location Blender applies"),
               ("OBJECT", "Armature Object", "The armature object itself")))

    def execute(self, context):
        obj = _armature(context)
        if obj is None:
            self.report({"ERROR"}, "Gait Setup needs an armature as the active object")
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
        selected = [pb.name for pb in (context.selected_pose_bones or [])] if context.mode == "POSE" else []
        if len(selected) == 4:
            rigmod.gait_frame(obj)
            legs, how = rigmod.find_legs_from_feet(armature, selected), "from the four selected feet"
        else:
            legs, how = rigmod.find_legs_by_name(armature), "by name"
        missing = [k for k in LEG_NAMES if k not in legs]
        if missing:
            found = ", ".join(f"{k} ({len(v)} bones)" for k, v in legs.items()) or "none"
            return (f"Found fewer than four legs {how}: found {found}; missing {', '.join(missing)}. "
                    "Name leg bones with a side (.L/.R, _l/_r, Left/Right, 'L ') and a limb (thigh, shin, foot, "
                    "upper_arm, forearm, hand, or fore/hind), or select the four foot bones in Pose Mode")
        for k in LEG_NAMES:
            if len(legs[k]) < 2:
                return (f"Leg {k} ('{legs[k][0]}') has a single bone; a leg needs 2 to 6 bones "
                        "(a bone from the body to the foot cannot bend)")
            if len(legs[k]) > 6:
                return f"Leg {k} has {len(legs[k])} bones ({' > '.join(legs[k])}); a leg needs 2 to 6"
        body = rigmod.find_body(armature, legs)
        root_motion = self.root_motion
        if root_motion == "AUTO":
            root_motion = "BONE" if body is not None else "OBJECT"
        if root_motion == "BONE" and body is None:
            return "No body bone: the four legs have no common parent bone to carry root motion " \
                   "(use Root Motion: Armature Object)"
        # Validate the geometry before touching the settings.
        forward = rigmod.forward_of(obj, legs)
        probe = {"forward": forward, "body_head": np.zeros(3), "body_rest": np.eye(3), "legs": []}
        ground = min(float(rigmod.leg_points(obj, legs[k])[1][2]) for k in LEG_NAMES)
        for k in LEG_NAMES:
            heads, tail = rigmod.leg_points(obj, legs[k])
            probe["legs"].append({"heads": heads, "tail": tail, "limit_min": np.full(len(heads), -1.0),
                                  "limit_max": np.full(len(heads), 1.0), "stiffness": np.ones(len(heads))})
            d = np.diff(np.vstack([heads, tail[None, :]]), axis=0)
            planar = float(np.hypot(d @ forward, d[:, 2]).sum())
            drop = float(heads[0][2]) - ground
            if drop > planar * 0.999:
                return (f"Leg {k} cannot reach the ground: its root '{legs[k][0]}' is {drop:.3g} m above the "
                        f"lowest foot but the leg is only {planar:.3g} m long")
        why = native.module().gait_validate_rig(probe)
        if why:
            return f"The legs cannot be solved: {why}"
        rigmod.fill_defaults(obj.kodawari_gait, obj, legs, body, preset=self.limits, root_motion=root_motion)
        summary = "; ".join(f"{k}: {' > '.join(legs[k])}" for k in LEG_NAMES)
        where = f"body bone '{body}'" if root_motion == "BONE" else "the armature object"
        self.report({"INFO"}, f"Found 4 legs {how}; root motion on {where}. {summary}")
        return None


class KODAWARI_OT_gait_bake(bpy.types.Operator):
    """Plan the gait from the speed curve, solve every leg, and bake it to an Action"""

    bl_idname = "kodawari.gait_bake"
    bl_label = "Bake Gait"
    bl_options = {"REGISTER", "UNDO"}

    frame_start: bpy.props.IntProperty(name="Start", default=1)
    frame_end: bpy.props.IntProperty(name="End", default=250)

    def _make_job(self, context):
        try:
            return GaitBakeJob(context, _armature(context) or context.active_object, self.frame_start,
                               self.frame_end)
        except ValueError as exc:
            self.report({"ERROR"}, f"Gait bake: {exc}")
            return None

    def execute(self, context):
        job = self._make_job(context)
        if job is None:
            return {"CANCELLED"}
        job.run()
        self.report({"INFO"}, f"Baked {len(job.frames)} frames of gait on '{job.obj.name}'")
        return {"FINISHED"}

    def invoke(self, context, event):
        if not self.properties.is_property_set("frame_start"):
            self.frame_start = context.scene.frame_start
        if not self.properties.is_property_set("frame_end"):
            self.frame_end = context.scene.frame_end
        if bpy.app.background:
            return self.execute(context)
        self._job = self._make_job(context)
        if self._job is None:
            return {"CANCELLED"}
        self._job.begin()
        self._steps = self._job.steps()
        wm = context.window_manager
        wm.progress_begin(0, 100)
        self._timer = wm.event_timer_add(0.01, window=context.window)
        wm.modal_handler_add(self)
        return {"RUNNING_MODAL"}

    def modal(self, context, event):
        wm = context.window_manager
        if event.type == "ESC":
            self._job.cancel()
            self._end(context)
            self.report({"WARNING"}, "Gait bake cancelled: nothing changed")
            return {"CANCELLED"}
        if event.type != "TIMER":
            return {"PASS_THROUGH"}
        try:
            fraction = next(self._steps)
            wm.progress_update(int(fraction * 100))
        except StopIteration:
            self._job.finish()
            self._end(context)
            self.report({"INFO"}, f"Baked {len(self._job.frames)} frames of gait on '{self._job.obj.name}'")
            return {"FINISHED"}
        return {"RUNNING_MODAL"}

    def _end(self, context):
        wm = context.window_manager
        wm.event_timer_remove(self._timer)
        wm.progress_end()


class KODAWARI_OT_gait_report(bpy.types.Operator):
    """Measure the baked gait: footfall diagram and fore-aft foot trajectories (PNG) and
    the seed's smoothness criteria per gait segment (JSON)"""

    bl_idname = "kodawari.gait_report"
    bl_label = "Gait Report"
    bl_options = {"REGISTER", "UNDO"}

    filepath: bpy.props.StringProperty(name="File Path", subtype="FILE_PATH", default="//gait_report.png")

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
