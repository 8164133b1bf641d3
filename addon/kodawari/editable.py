"""Refuse to change data linked from another .blend: Blender keeps none of those changes
on save (the library file is the truth), so a creature set up on it would be lost."""

from bpy.app.translations import pgettext_tip as tip_


def why_not(obj, doing):
    """A user's sentence when obj (or its object data) cannot keep changes, else None."""
    if obj is None:
        return None
    if obj.library is not None:
        return tip_(
            "'{}' is linked from '{}' and cannot {} here (changes would be lost on save): set it up in that file, or make a Library Override"
        ).format(obj.name, obj.library.filepath, doing)
    data = getattr(obj, "data", None)
    if data is not None and getattr(data, "library", None) is not None and obj.type == "MESH":
        return tip_(
            "The mesh of '{}' is linked from '{}': make it local (Object > Relations > Make Local) first"
        ).format(obj.name, data.library.filepath)
    return None
