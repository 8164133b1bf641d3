"""Every user-visible string the registered Kodawari classes carry in RNA: operator names
and tooltips, property names and tooltips, enum item names and tooltips, panel and menu
titles. Walked from the classes themselves, so a string added later is never missed by
the tooltip and translation checks (tests/blender/test_ui_*.py, tools/i18n_missing.py)."""

import bpy

SKIPPED = {"rna_type"}


class UIString:
    """One string: where it comes from (for messages) and what it says."""

    def __init__(self, owner, field, text):
        self.owner, self.field, self.text = owner, field, text

    def __repr__(self):
        return f"{self.owner} {self.field}: {self.text!r}"


def _operator_rna(cls):
    module, name = cls.bl_idname.split(".")
    return getattr(getattr(bpy.ops, module), name).get_rna_type()


def _own_properties(cls, rna):
    annotated = set()
    for base in cls.__mro__:
        annotated |= set(getattr(base, "__annotations__", {}))
    for prop in rna.properties:
        if prop.identifier in SKIPPED:
            continue
        if prop.identifier in annotated:
            yield prop


def _property_strings(owner, prop):
    yield UIString(owner, f"{prop.identifier}.name", prop.name)
    yield UIString(owner, f"{prop.identifier}.description", prop.description)
    if prop.type == "ENUM":
        for item in prop.enum_items:
            yield UIString(owner, f"{prop.identifier}[{item.identifier}].name", item.name)
            yield UIString(
                owner, f"{prop.identifier}[{item.identifier}].description", item.description
            )


def walk(classes):
    """UIString for every label and tooltip of the given registered classes."""
    for cls in classes:
        if issubclass(cls, bpy.types.Operator):
            rna = _operator_rna(cls)
            yield UIString(cls.bl_idname, "label", rna.name)
            yield UIString(cls.bl_idname, "description", rna.description)
            for prop in _own_properties(cls, rna):
                yield from _property_strings(cls.bl_idname, prop)
        elif issubclass(cls, (bpy.types.Panel, bpy.types.Menu)):
            yield UIString(cls.__name__, "label", cls.bl_label)
        elif issubclass(cls, (bpy.types.PropertyGroup, bpy.types.AddonPreferences)):
            for prop in _own_properties(cls, cls.bl_rna):
                yield from _property_strings(cls.__name__, prop)


def registered():
    from .. import registration

    return list(walk(registration.registered_classes()))
