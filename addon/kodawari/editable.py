"""Refuse to change data linked from another .blend: Blender keeps none of those changes
on save (the library file is the truth), so a creature set up on it would be lost."""


def why_not(obj, doing):
    """A user's sentence when obj (or its object data) cannot keep changes, else None."""
    if obj is None:
        return None
    if obj.library is not None:
        return (
            f"'{obj.name}' is linked from '{obj.library.filepath}' and cannot {doing} here "
            "(changes would be lost on save): set it up in that file, or make a Library Override"
        )
    data = getattr(obj, "data", None)
    if data is not None and getattr(data, "library", None) is not None and obj.type == "MESH":
        return (
            f"The mesh of '{obj.name}' is linked from '{data.library.filepath}': "
            "make it local (Object > Relations > Make Local) first"
        )
    return None
