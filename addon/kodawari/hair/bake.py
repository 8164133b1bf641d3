"""Baking the rods into F-curves (rotation_quaternion), so renders and exports need no
add-on. The bake simulates with its own runtime, frame by frame from the scene's start
(where live simulation resets too), not through the live frame handler: the live
simulation is switched off for the bake and everything it touched is put back."""

import bpy
import numpy as np
from bpy.app.translations import pgettext_tip as tip_

from .. import editable, fcurves
from ..bake_job import BakeError, BakeJob
from . import runtime

NLA_TRACK = "Kodawari Hair Bake"


class HairBakeJob(BakeJob):
    title = "Hair bake"

    def __init__(self, obj, scene, frame_start, frame_end, new_action=False):
        self.obj, self.scene = obj, scene
        self.start, self.end = frame_start, frame_end
        self.first = min(
            scene.frame_start, frame_start
        )  # live resets at the scene's start: so does the bake
        self.frame = self.first
        self.new_action = new_action
        self.baked = {}
        self.chains = []
        self.snapshot = None
        self.created = None  # (action, NLA track) made by finish, removed by cancel

    def prepare(self):
        obj, scene = self.obj, self.scene
        why = editable.why_not(obj, tip_("bake its hair"))
        if why:
            raise BakeError(why)
        settings = obj.kodawari_hair
        if not len(settings.rods):
            raise BakeError(tip_("This armature has no rods to bake"))
        self.rt = runtime.ArmatureRuntime(obj)  # validates every rod before anything changes
        if self.rt.error:
            raise BakeError(self.rt.error)
        self.chains = [name for i in sorted(self.rt.rod_chains) for name in self.rt.rod_chains[i]]
        pose = obj.pose.bones
        rotations = np.empty(len(pose) * 4, np.float32)
        pose.foreach_get("rotation_quaternion", rotations)
        anim = obj.animation_data
        self.snapshot = {
            "frame": (scene.frame_current, scene.frame_subframe),
            "enabled": settings.enabled,
            "rotations": rotations,
            "action": anim.action if anim is not None else None,
            "has_anim": anim is not None,
        }
        # The live handler must not simulate this armature while the bake does.
        settings.enabled = False

    def step(self):
        obj, scene = self.obj, self.scene
        scene.frame_set(self.frame)
        self.rt.evaluate(obj, scene, self.frame)
        if self.frame >= self.start:
            self.baked[self.frame] = self.rt.cached_rotations(self.frame)
        self.frame += 1
        return (self.frame - self.first) / (self.end + 1 - self.first)

    def cancel(self):
        if self.snapshot is None:
            return
        obj, snap = self.obj, self.snapshot
        if self.created is not None:
            action, track = self.created
            anim = obj.animation_data
            if track is not None and anim is not None:
                anim.nla_tracks.remove(track)
            if anim is not None and anim.action is action:
                anim.action = snap["action"]
            if action is not snap["action"]:
                bpy.data.actions.remove(action)
            self.created = None
        if (
            not snap["has_anim"]
            and obj.animation_data is not None
            and obj.animation_data.action is None
        ):
            obj.animation_data_clear()
        obj.pose.bones.foreach_set("rotation_quaternion", snap["rotations"])
        obj.kodawari_hair.enabled = snap["enabled"]
        obj.update_tag(refresh={"OBJECT"})
        self.scene.frame_set(snap["frame"][0], subframe=snap["frame"][1])
        self.snapshot = None

    def finish(self):
        obj = self.obj
        frames = np.array(sorted(self.baked), dtype=np.float32)
        values = np.stack([self.baked[int(f)] for f in frames])  # (F, bones, 4)
        anim = obj.animation_data or obj.animation_data_create()
        if self.new_action:
            previous = anim.action
            previous_slot = getattr(anim, "action_slot", None)
            anim.action = None
            action = fcurves.ensure_action(obj, f"{obj.name}_HairBake")
            track = anim.nla_tracks.new()
            self.created = (action, track)
            self._write(action, frames, values)
            track.name = NLA_TRACK
            strip = track.strips.new(action.name, int(frames[0]), action)
            if hasattr(strip, "action_slot") and strip.action_slot is None and len(action.slots):
                strip.action_slot = action.slots[0]
            anim.action = previous
            if previous is not None and previous_slot is not None:
                anim.action_slot = previous_slot
        else:
            existing = anim.action
            action = fcurves.ensure_action(obj, f"{obj.name}Action")
            if action is not existing:
                self.created = (action, None)
            self._write(action, frames, values)
        # The bake now plays back: the live simulation would only repeat it.
        snap = self.snapshot
        obj.kodawari_hair.enabled = False
        self.scene.frame_set(snap["frame"][0], subframe=snap["frame"][1])
        self.snapshot = None
        return tip_(
            "Baked {} bones over frames {}-{} into action '{}'{}; live simulation turned off"
        ).format(
            len(self.chains),
            self.start,
            self.end,
            action.name,
            tip_(" (NLA track)") if self.new_action else "",
        )

    def _write(self, action, frames, values):
        for b, name in enumerate(self.chains):
            fcurves.write_channels(
                action,
                self.obj,
                f'pose.bones["{name}"].rotation_quaternion',
                frames,
                values[:, b, :],
                group=name,
            )
