"""Everything the add-on adds to Blender, in order, and how to take it away again.

Each feature package (fish/, hair/, gait/) exposes three lists:
  CLASSES     bpy classes in registration order (property groups before users)
  PROPERTIES  (owner type, attribute name, property factory) root properties
  HANDLERS    (bpy.app.handlers list name, @persistent function)
and registration here is the only place that touches bpy.utils / bpy.types.
"""

import importlib

import bpy

from . import menus, native, preferences, problems, sidebar, translations

FEATURE_PACKAGES = ("fish", "hair", "gait")

_registered_classes = []
_registered_properties = []
_registered_handlers = []
_appended_menu_functions = []


def registered_classes():
    """Every class the add-on registered, in order (the menus and tests walk these)."""
    return tuple(_registered_classes)


def _features():
    found = []
    for name in FEATURE_PACKAGES:
        try:
            found.append(importlib.import_module(f".{name}", __package__))
        except ModuleNotFoundError as exc:
            # A feature folder that is not in this build yet; any other import error is a bug.
            if exc.name != f"{__package__}.{name}":
                raise
    return found


def _register_class(cls):
    bpy.utils.register_class(cls)
    _registered_classes.append(cls)


def register():
    try:
        _register_class(preferences.KodawariPreferences)
        _register_class(preferences.KODAWARI_OT_native_report)
        _register_class(problems.KODAWARI_OT_report_problem)
        if not native.available():
            # Enable anyway, tools off; say why in the preferences and the report area.
            print(f"Kodawari: {native.error()}")
            if not bpy.app.background:
                bpy.app.timers.register(_report_native_error, first_interval=0.5)
            return
        for feature in _features():
            for cls in feature.CLASSES:
                _register_class(cls)
            for owner, attribute, factory in feature.PROPERTIES:
                setattr(owner, attribute, factory())
                _registered_properties.append((owner, attribute))
            for list_name, function in feature.HANDLERS:
                getattr(bpy.app.handlers, list_name).append(function)
                _registered_handlers.append((list_name, function))
        # The user interface around the features: menus, sidebar tab, translations.
        for cls in menus.CLASSES + sidebar.CLASSES:
            _register_class(cls)
        _appended_menu_functions.extend(menus.append())
        translations.register()
    except Exception:
        # Never leave a half-registered add-on behind.
        unregister()
        raise


def _report_native_error():
    try:
        bpy.ops.kodawari.native_report()
    except RuntimeError:
        pass  # the operator reports by cancelling, which bpy.ops raises on; the message is shown
    return None


def unregister():
    translations.unregister()
    while _appended_menu_functions:
        menu, function = _appended_menu_functions.pop()
        menu.remove(function)
    while _registered_handlers:
        list_name, function = _registered_handlers.pop()
        handlers = getattr(bpy.app.handlers, list_name)
        if function in handlers:
            handlers.remove(function)
    while _registered_properties:
        owner, attribute = _registered_properties.pop()
        if hasattr(owner, attribute):
            delattr(owner, attribute)
    while _registered_classes:
        cls = _registered_classes.pop()
        if getattr(cls, "is_registered", True):
            bpy.utils.unregister_class(cls)
