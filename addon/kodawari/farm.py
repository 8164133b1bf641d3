"""Headless baking for render farms: bake every creature of the open .blend, save it, and
say (exit code) whether everything baked. A baked file renders the same on a Blender
without Kodawari: gaits and hair are Actions, fish play a PC2 through Blender's Mesh
Cache modifier from `//blendcache_<file>/`, relative to the .blend.

    blender -b shot.blend --python-expr "import kodawari; kodawari.bake_all()"

Order matters: gaits first (hair may hang from a galloping horse), then fish, then hair.
"""

import os
import sys

import bpy
from bpy.app.translations import pgettext_tip as tip_

from . import bake_job
from .bake_job import BakeError


class _SceneContext:
    """The two things a gait bake reads from the context, for a scene that is not the active one."""

    def __init__(self, scene):
        self.scene = scene

    def evaluated_depsgraph_get(self):
        return self.scene.view_layers[0].depsgraph


def _ensure_registered():
    # `import kodawari` on a worker whose preferences do not enable the add-on: enable it now.
    if not hasattr(bpy.types.Object, "kodawari_swim"):
        import addon_utils

        addon_utils.enable(__package__, default_set=False)
    if not hasattr(bpy.types.Object, "kodawari_swim"):
        from . import native

        raise BakeError(
            tip_("Kodawari could not start: {}").format(
                native.error() or tip_("the add-on did not register")
            )
        )


def _gait_ready(obj):
    settings = obj.kodawari_gait
    return len(settings.legs) == 4 and bool(settings.body_bone)


def _jobs(scene, context):
    """(object name, job) for every creature of the scene that still needs a bake."""
    from .fish import bake as fish_bake
    from .fish import visibility as fish_visibility
    from .gait.bake import GaitBakeJob
    from .hair.bake import HairBakeJob

    start, end = scene.frame_start, scene.frame_end
    objects = [obj for obj in scene.objects if obj.library is None]
    for obj in objects:
        if obj.type == "ARMATURE" and _gait_ready(obj):
            yield obj.name, lambda obj=obj: GaitBakeJob(context, obj, start, end)
    for obj in objects:
        if obj.type == "MESH" and fish_visibility.renders(
            obj
        ):  # what the render shows, not the viewport
            yield (
                obj.name,
                lambda obj=obj: fish_bake.SwimBakeJob(obj, scene, start, end, "MESH_CACHE"),
            )
    for obj in objects:
        if obj.type == "ARMATURE" and obj.kodawari_hair.enabled and len(obj.kodawari_hair.rods):
            yield obj.name, lambda obj=obj: HairBakeJob(obj, scene, start, end)


def bake_all(save=True, exit_on_failure=None):
    """Bake every creature (gait, fish swim, hair) of every scene in the open file over the
    scene's frame range, then save the file (save=False: do not).

    Returns the report lines. When anything fails, the other creatures still bake and
    the successes are saved; then, run by the Blender program in background
    (`blender -b`), Blender exits with code 1; otherwise (the bpy module, a script with
    exit_on_failure=False) BakeError is raised listing every failure."""
    if exit_on_failure is None:
        exit_on_failure = bpy.app.background and bool(bpy.app.binary_path)
    try:
        _ensure_registered()
        if not bpy.data.filepath:
            raise BakeError(
                tip_(
                    "Save the file first: caches are written beside the .blend, in a folder named after it"
                )
            )
        done, failed = _bake_scenes()
        if save and done:
            bpy.ops.wm.save_mainfile()
    except BakeError as exc:
        done, failed = [], [str(exc)]
    for line in done:
        print(f"Kodawari bake_all: {line}")
    for line in failed:
        print(f"Kodawari bake_all: FAILED {line}")
    print(f"Kodawari bake_all: {len(done)} baked, {len(failed)} failed")
    sys.stdout.flush()
    if failed:
        if exit_on_failure:
            sys.exit(1)
        raise BakeError("; ".join(failed))
    return done


def _missing_caches(scene):
    """Fish baked earlier whose PC2 is not where the file looks: they would render frozen."""
    for obj in scene.objects:
        for modifier in getattr(obj, "modifiers", ()):
            if modifier.type == "MESH_CACHE" and obj.kodawari_swim.baked == "MESH_CACHE":
                path = bpy.path.abspath(modifier.filepath, library=obj.library)
                if not os.path.isfile(path):
                    yield (
                        f"{scene.name}/{obj.name}: its cache '{modifier.filepath}' is missing: "
                        "copy the blendcache folder with the .blend, or Free Bake and bake again"
                    )


def _bake_scenes():
    done, failed = [], []
    active = bpy.context.scene
    for scene in bpy.data.scenes:
        failed.extend(_missing_caches(scene))
        context = bpy.context if scene == active else _SceneContext(scene)
        for name, make in list(_jobs(scene, context)):
            try:
                try:
                    job = make()
                except ValueError as exc:  # a gait that cannot be solved refuses in its constructor
                    raise BakeError(tip_("Gait bake: {}").format(exc)) from None
                done.append(f"{scene.name}/{name}: {bake_job.run(job)}")
            except BakeError as exc:
                failed.append(f"{scene.name}/{name}: {exc}")
    return done, failed
