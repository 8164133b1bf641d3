"""Persistent application handlers: live simulation, save/reload, undo."""

import bpy
from bpy.app.handlers import persistent

from .. import problems
from . import chains, runtime


@persistent
def on_frame_change(scene, depsgraph=None):
    runtime.evaluate_scene(scene, depsgraph)


@persistent
def on_frame_change_pre(scene, depsgraph=None):
    runtime.show_cached_frames(scene)


@persistent
def on_load(filepath=None):
    runtime.clear()
    for obj in bpy.data.objects:
        if obj.type == "ARMATURE" and len(obj.kodawari_hair.rods):
            try:
                for (
                    rod
                ) in obj.kodawari_hair.rods:  # rods from before roots were tagged: tag them now
                    if not rod.uid and rod.root_bone in obj.pose.bones:
                        chains.tag_root(obj.pose.bones[rod.root_bone], rod)
                runtime.restore_state(obj)
            except Exception as exc:  # noqa: BLE001 - one broken rig never stops the others
                problems.report(obj, "hair", exc)


@persistent
def on_save(filepath=None):
    for obj in bpy.data.objects:
        if obj.type == "ARMATURE" and len(obj.kodawari_hair.rods):
            runtime.store_state(obj)


@persistent
def on_undo(scene=None, depsgraph=None):
    # Undo replaced the data: runtimes rebuild from the restored settings.
    runtime.clear()
