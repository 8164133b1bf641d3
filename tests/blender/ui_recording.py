"""A recording stand-in for UILayout, shared by the UI tests.

Background Blender never draws panels or menus, so draw() functions run here against
a layout that accepts only what the running Blender's UILayout offers, checks every
property and operator named against RNA, and records what would be drawn: props
(with whether use_property_split was on), labels, operators, menus, lists."""

import bpy

UILAYOUT_FUNCTIONS = set(bpy.types.UILayout.bl_rna.functions.keys())
UILAYOUT_PROPERTIES = set(bpy.types.UILayout.bl_rna.properties.keys())
ICONS = {
    item.identifier
    for item in bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items
}


def _has_property(data, name):
    return name in data.bl_rna.properties or (isinstance(data, bpy.types.ID) and name in data)


class Entry:
    """One drawn element: kind ("prop", "label", "operator", "menu", ...), name, keywords."""

    def __init__(self, kind, name, split, in_list, kwargs):
        self.kind, self.name, self.split, self.in_list, self.kwargs = (
            kind,
            name,
            split,
            in_list,
            kwargs,
        )

    def __str__(self):
        return f"{self.kind} {self.name}"

    def __eq__(self, other):
        return str(self) == other if isinstance(other, str) else self is other

    def startswith(self, prefix):
        return str(self).startswith(prefix)


class OperatorCall:
    def __init__(self, idname, entry):
        module, name = idname.split(".")
        self.__dict__["_rna"] = getattr(getattr(bpy.ops, module), name).get_rna_type()
        self.__dict__["_entry"] = entry

    def __setattr__(self, name, value):
        assert name in self._rna.properties, (
            f"operator {self._rna.identifier} has no property {name!r}"
        )
        self._entry.kwargs.setdefault("properties", {})[name] = value


class RecordingLayout:
    """Duck-types UILayout: checks names, records what would be drawn."""

    def __init__(self, log, split=False, in_list=False):
        self.__dict__.update(log=log, _split=split, in_list=in_list)

    def __setattr__(self, name, value):
        assert name in UILAYOUT_PROPERTIES, f"UILayout has no attribute {name!r} in this Blender"
        if name == "use_property_split":
            self.__dict__["_split"] = bool(value)

    def __getattr__(self, name):
        assert name in UILAYOUT_FUNCTIONS, f"UILayout has no function {name!r} in this Blender"
        return lambda *args, **kwargs: self._generic(name, args, kwargs)

    def _record(self, kind, name, kwargs):
        icon = kwargs.get("icon")
        assert icon is None or icon in ICONS, f"no icon {icon!r} in this Blender"
        entry = Entry(kind, name, self._split, self.in_list, kwargs)
        self.log.append(entry)
        return entry

    def _child(self):
        return RecordingLayout(self.log, self._split, self.in_list)

    def _generic(self, name, args, kwargs):
        self._record(name, "", kwargs)
        return self._child()

    def prop(self, data, name, **kwargs):
        assert _has_property(data, name.strip('[]"')), (
            f"{type(data).__name__} has no property {name!r}"
        )
        self._record("prop", name, dict(kwargs, data=data))

    def prop_search(self, data, name, search_data, search_name, **kwargs):
        assert _has_property(data, name), f"{type(data).__name__} has no property {name!r}"
        assert _has_property(search_data, search_name), (
            f"{type(search_data).__name__} has no {search_name!r}"
        )
        self._record("prop_search", name, dict(kwargs, data=data))

    def label(self, **kwargs):
        self._record("label", kwargs.get("text", ""), kwargs)

    def menu(self, menu, **kwargs):
        assert hasattr(bpy.types, menu), f"no menu {menu!r} registered"
        self._record("menu", menu, kwargs)

    def operator(self, idname, **kwargs):
        entry = self._record("operator", idname, kwargs)
        return OperatorCall(idname, entry)

    def template_list(self, list_type, list_id, data, name, active_data, active_name, **kwargs):
        assert _has_property(data, name) and _has_property(active_data, active_name)
        list_class = getattr(bpy.types, list_type)
        for index, item in enumerate(getattr(data, name)):
            call(
                list_class.draw_item,
                list_class,
                bpy.context,
                RecordingLayout(self.log, False, True),
                data,
                item,
                0,
                active_data,
                active_name,
                index,
            )
        self._record("template_list", name, kwargs)


def call(function, owner, context, layout, *args):
    """Calls a Panel/Menu/UIList method on a stand-in instance (bpy classes cannot be instantiated)."""

    class StandIn:
        def __getattr__(self, name):
            value = getattr(owner, name)
            return value.__get__(self) if callable(value) and hasattr(value, "__get__") else value

    stand_in = StandIn()
    stand_in.layout = layout
    return (
        function(stand_in, context, *args)
        if not args
        else function(stand_in, context, layout, *args)
    )


def kodawari_classes(prefix):
    return [getattr(bpy.types, name) for name in dir(bpy.types) if name.startswith(prefix)]


def draw_panel(panel, context=None):
    """Everything one panel draws (header and body)."""
    log = []
    for method in ("draw_header", "draw"):
        if hasattr(panel, method):
            call(getattr(panel, method), panel, context or bpy.context, RecordingLayout(log))
    return log


def draw_body(panel, context=None):
    log = []
    call(panel.draw, panel, context or bpy.context, RecordingLayout(log))
    return log


def showing_panels(prefix, context=None):
    """{panel name: what it draws} for every Kodawari panel with `prefix` that shows now."""
    return {
        panel.__name__: draw_panel(panel, context)
        for panel in kodawari_classes(prefix)
        if panel.poll(context or bpy.context)
    }


def draw_menu_function(function, menu_class, context=None):
    log = []
    call(function, menu_class, context or bpy.context, RecordingLayout(log))
    return log
