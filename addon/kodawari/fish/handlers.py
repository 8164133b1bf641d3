"""Persistent application handlers of the fish swim: live evaluation on frame changes,
the swim pose on file load, and the render toggles while a render runs."""

import bpy
from bpy.app.handlers import persistent

from .. import problems
from . import runtime, visibility

_edited = set()  # meshes whose geometry changed since the last frame (depsgraph updates)


def _collect_meshes(depsgraph, into):
    for update in depsgraph.updates:
        if update.is_updated_geometry and isinstance(update.id, bpy.types.Mesh):
            into.add(update.id.original.as_pointer())


@persistent
def on_depsgraph_update(scene, depsgraph=None):
    # Operators (Apply Scale, leaving Edit Mode) report their edits here, not to the
    # frame handler.
    if depsgraph is not None:
        _collect_meshes(depsgraph, _edited)


def _changed_meshes(depsgraph):
    """Meshes whose geometry changed since the last frame (edited, Apply Scale, Edit Mode
    left): only their rest shape is compared with the bound one (a full read)."""
    if depsgraph is None:
        return None  # unknown: compare every swimmer's
    changed = set(_edited)
    _edited.clear()
    _collect_meshes(depsgraph, changed)
    return changed


@persistent
def on_frame_change(scene, depsgraph=None):
    runtime.separate_linked_duplicates(scene)
    changed = _changed_meshes(depsgraph)
    for obj in scene.objects:
        if obj.type != "MESH":
            continue
        visibility.pull(obj)  # a click on the Fish Swim modifier's own eye or camera
        if not runtime.is_live(obj):
            continue
        check = changed is None or obj.data.as_pointer() in changed
        if check and changed is not None and runtime.consume_own_update(obj):
            check = False  # the change Blender reports is the route's own attributes
        try:
            runtime.evaluate(obj, scene, check_rest=check)
        except Exception as exc:  # noqa: BLE001 - one broken fish never stops the others
            problems.report(obj, "swim", exc)
        else:
            problems.clear(obj, "swim")
    runtime.release_setup_scratch()


@persistent
def on_load(_dummy=None, *_args):
    # Rigs belong to the old file's objects; the first frame change rebuilds them
    # from the saved settings. Evaluate now so the opened file shows the swim pose.
    runtime.forget()
    scene = bpy.context.scene
    if scene is None:
        return
    for obj in scene.objects:
        if obj.type == "MESH" and runtime.is_live(obj):
            try:
                runtime.evaluate(obj, scene)
            except Exception as exc:  # noqa: BLE001 - one broken fish never stops the others
                problems.report(obj, "swim", exc)


@persistent
def on_render_init(scene, *_args):
    visibility.set_rendering(scene, True)


@persistent
def on_render_pre(scene, *_args):
    visibility.set_rendering(scene, True)


@persistent
def on_render_done(scene, *_args):
    visibility.set_rendering(scene, False)
