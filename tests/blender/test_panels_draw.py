"""Every Kodawari panel and list draws without error on every Blender.

Background Blender never draws panels, so a draw() bug would only show in the UI.
Here each panel's draw() runs against a recording layout that accepts only what
the running Blender's UILayout offers, and checks every property and operator it
names against RNA: a typo, or an API newer than this Blender, fails the test."""

import bpy
import pytest
from fish_helpers import add_swim, make_fish
from gait_scene import horse
from hair_rig import add_camera, make_rig, select_only

UILAYOUT_FUNCTIONS = set(bpy.types.UILayout.bl_rna.functions.keys())
UILAYOUT_PROPERTIES = set(bpy.types.UILayout.bl_rna.properties.keys())


def _has_property(data, name):
    return name in data.bl_rna.properties or (isinstance(data, bpy.types.ID) and name in data.keys())


class OperatorCall:
    def __init__(self, idname):
        module, name = idname.split(".")
        self.__dict__["_rna"] = getattr(getattr(bpy.ops, module), name).get_rna_type()

    def __setattr__(self, name, value):
        assert name in self._rna.properties, f"operator {self._rna.identifier} has no property {name!r}"


class RecordingLayout:
    """Duck-types UILayout: checks names, records what would be drawn."""

    def __init__(self, log):
        self.__dict__["log"] = log

    def __setattr__(self, name, value):
        assert name in UILAYOUT_PROPERTIES, f"UILayout has no attribute {name!r} in this Blender"

    def __getattr__(self, name):
        assert name in UILAYOUT_FUNCTIONS, f"UILayout has no function {name!r} in this Blender"
        return lambda *args, **kwargs: self._generic(name, args, kwargs)

    def _generic(self, name, args, kwargs):
        self.log.append(name)
        return RecordingLayout(self.log)

    def prop(self, data, name, **kwargs):
        assert _has_property(data, name.strip('[]"')), f"{type(data).__name__} has no property {name!r}"
        self.log.append(f"prop {name}")

    def prop_search(self, data, name, search_data, search_name, **kwargs):
        assert _has_property(data, name), f"{type(data).__name__} has no property {name!r}"
        assert _has_property(search_data, search_name), f"{type(search_data).__name__} has no {search_name!r}"
        self.log.append(f"prop_search {name}")

    def operator(self, idname, **kwargs):
        self.log.append(f"operator {idname}")
        return OperatorCall(idname)

    def template_list(self, list_type, list_id, data, name, active_data, active_name, **kwargs):
        assert _has_property(data, name) and _has_property(active_data, active_name)
        list_class = getattr(bpy.types, list_type)
        for index, item in enumerate(getattr(data, name)):
            call(list_class.draw_item, list_class, bpy.context, RecordingLayout(self.log), data, item, 0,
                 active_data, active_name, index)
        self.log.append(f"template_list {name}")


def call(function, owner, context, layout, *args):
    """Calls a Panel/UIList method on a stand-in instance (bpy classes cannot be instantiated)."""

    class StandIn:
        def __getattr__(self, name):
            value = getattr(owner, name)
            return value.__get__(self) if callable(value) and hasattr(value, "__get__") else value

    stand_in = StandIn()
    stand_in.layout = layout
    return function(stand_in, context, *args) if not args else function(stand_in, context, layout, *args)


def draw_panels(prefix):
    panels = [getattr(bpy.types, name) for name in dir(bpy.types) if name.startswith(prefix)]
    assert panels, f"no panel {prefix}* registered"
    logs = {}
    for panel in panels:
        assert panel.poll(bpy.context), f"{panel.__name__} does not show for this object"
        log = []
        for method in ("draw_header", "draw"):
            if hasattr(panel, method):
                call(getattr(panel, method), panel, bpy.context, RecordingLayout(log))
        logs[panel.__name__] = log
    return logs


def test_fish_panel_draws(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral", "fin_dorsal"))
    log = draw_panels("KODAWARI_PT_swim")["KODAWARI_PT_swim"]
    assert "prop frequency" in log and "template_list fins" in log
    assert any(entry.startswith("operator kodawari.swim_bake") for entry in log)


def test_hair_panel_draws(empty_scene):
    obj = make_rig(empty_scene)
    add_camera(empty_scene, "Front", (0.0, -3.0, 1.7))
    select_only(obj, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    assert bpy.ops.kodawari.rod_key_view(source="CAMERA") == {"FINISHED"}
    log = draw_panels("KODAWARI_PT_hair")["KODAWARI_PT_hair"]
    assert "template_list rods" in log and "template_list keys" in log
    assert any(entry.startswith("operator kodawari.rod_bake") for entry in log)


def test_gait_panel_draws(empty_scene):
    horse(empty_scene, speeds=((1, 2.0), (48, 5.0)))
    log = draw_panels("KODAWARI_PT_gait")["KODAWARI_PT_gait"]
    assert "prop speed" in log
    assert any(entry.startswith("operator kodawari.gait_bake") for entry in log)


@pytest.mark.parametrize("prefix", ["KODAWARI_PT_swim", "KODAWARI_PT_hair", "KODAWARI_PT_gait"])
def test_panels_hide_for_objects_they_do_not_serve(empty_scene, prefix):
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    empty_scene.collection.objects.link(camera)
    bpy.context.view_layer.objects.active = camera
    for name in dir(bpy.types):
        if name.startswith(prefix):
            assert not getattr(bpy.types, name).poll(bpy.context)
