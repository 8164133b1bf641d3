"""Where bakes write their files, the way Blender's own disk caches do: beside the saved
.blend, in a folder named after it (`//blendcache_<file name>/`), one file per object.

A cache is never written over another object's cache in this file (names get a number
until unique), nor into another file's folder; an unsaved file has no folder yet, so
the user is asked to save first. Every check runs before the first frame is baked.
"""

import os

import bpy
from bpy.app.translations import pgettext_tip as tip_

from .bake_job import BakeError

FOLDER_PREFIX = "blendcache_"
# File-path properties that hold `//` paths say so from Blender 4.5 (older ones refuse the flag).
RELATIVE_PATH_OPTIONS = {"PATH_SUPPORTS_BLEND_RELATIVE"} if bpy.app.version >= (4, 5, 0) else set()
SAVE_FIRST = "Save the file first: caches are written beside the .blend, in a folder named after it"


def blend_folder():
    """`//blendcache_<name>/` of the open file (Blender's point-cache folder convention)."""
    if not bpy.data.filepath:
        raise BakeError(tip_(SAVE_FIRST))
    stem = os.path.splitext(os.path.basename(bpy.data.filepath))[0]
    return f"//{FOLDER_PREFIX}{stem}/"


def _absolute(path, library=None):
    return os.path.normpath(bpy.path.abspath(path, library=library)) if path else ""


def caches_in_use(except_obj=None):
    """{absolute path: object name} of every cache file an object of this file plays."""
    used = {}
    for obj in bpy.data.objects:
        if obj == except_obj:
            continue
        for modifier in getattr(obj, "modifiers", ()):
            if modifier.type == "MESH_CACHE" and modifier.filepath:
                used[_absolute(modifier.filepath, obj.library)] = obj.name
    return used


def default_path(obj, suffix, extension):
    """A cache path for obj in this file's cache folder, used by no other object."""
    folder = blend_folder()
    base = bpy.path.clean_name(obj.name) + "_" + suffix
    used = caches_in_use(except_obj=obj)
    path, number = f"{folder}{base}{extension}", 1
    while _absolute(path) in used:
        path, number = f"{folder}{base}_{number}{extension}", number + 1
    return path


def check_target(obj, path):
    """The absolute file a bake of obj may write `path` to; BakeError says why not."""
    if path.startswith("//") and not bpy.data.filepath:
        raise BakeError(tip_("{} ('{}' is relative to it)").format(tip_(SAVE_FIRST), path))
    target = _absolute(path)
    if path.endswith(("/", "\\")) or os.path.isdir(target):
        raise BakeError(
            tip_("'{}' is a folder: give a file name, such as {}.pc2").format(
                path, bpy.path.clean_name(obj.name)
            )
        )
    owner = caches_in_use(except_obj=obj).get(target)
    if owner is not None:
        raise BakeError(tip_("'{}' is the cache of '{}': choose another file").format(path, owner))
    folder = os.path.dirname(target)
    parent = folder
    while parent and not os.path.exists(parent):
        parent = os.path.dirname(parent)
    if parent and not os.path.isdir(parent):
        raise BakeError(
            tip_("Cannot write '{}': '{}' is a file, not a folder").format(path, parent)
        )
    return target


def open_partial(target):
    """Create the folder and open `<target>.part` for writing: a folder that cannot be
    written fails here, before any frame is baked. The caller renames it when done."""
    try:
        os.makedirs(os.path.dirname(target) or ".", exist_ok=True)
        # Kept open across the bake's steps; closed by the job's finish() or cancel().
        return open(target + ".part", "wb")
    except OSError as exc:
        raise BakeError(
            tip_("Cannot write the cache '{}': {}").format(target, exc.strerror or exc)
        ) from exc


def discard_partial(handle, target):
    """Close and delete a `.part` file; quiet when it is already gone."""
    if handle is not None and not handle.closed:
        handle.close()
    try:
        os.remove(target + ".part")
    except FileNotFoundError:
        pass


def stored_path(target):
    """How a modifier stores the cache: relative to the saved .blend, so both travel together."""
    if bpy.data.filepath:
        try:
            return bpy.path.relpath(target)
        except ValueError:  # another drive (Windows): only an absolute path reaches it
            return target
    return target


def is_own_cache(path):
    """True when path lies in this file's cache folder (safe to delete on Free Bake)."""
    if not bpy.data.filepath or not path:
        return False
    own = _absolute(blend_folder())
    return os.path.dirname(_absolute(path)) == own
