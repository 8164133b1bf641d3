"""Every Kodawari panel and list draws without error on every Blender, in Blender's
own layout (split labels with decorators), and shows only on objects that use its
feature, with one "Add …" entry on the others.

Background Blender never draws panels, so a draw() bug would only show in the UI;
ui_recording.RecordingLayout runs draw() and checks every name against RNA."""

import bpy
import pytest
from fish_helpers import add_swim, make_fish
from gait_scene import horse
from hair_rig import add_camera, make_rig, select_only
from ui_recording import draw_body, kodawari_classes, showing_panels

SETTINGS_PANELS = {
    "KODAWARI_PT_swim": "swim",
    "KODAWARI_PT_hair": "hair",
    "KODAWARI_PT_gait": "gait",
}


def _settings_panels(prefix):
    return [p for p in kodawari_classes(prefix) if not p.__name__.endswith("_add")]


def _hair_rig(scene):
    obj = make_rig(scene)
    add_camera(scene, "Front", (0.0, -3.0, 1.7))
    select_only(obj, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    assert bpy.ops.kodawari.rod_key_view(source="CAMERA") == {"FINISHED"}
    assert bpy.ops.kodawari.rod_collider_add(bone="Ahoge.00") == {"FINISHED"}
    return obj


def _gait_horse(scene):
    obj = horse(scene, speeds=((1, 2.0), (48, 5.0)))
    bpy.context.view_layer.objects.active = obj
    return obj


def _all_entries(logs):
    return [entry for log in logs.values() for entry in log]


def test_fish_panels_draw(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj, fins=("fin_pectoral", "fin_dorsal"))
    logs = showing_panels("KODAWARI_PT_swim")
    entries = _all_entries(logs)
    assert "prop frequency" in entries and "template_list fins" in entries
    assert any(e.startswith("operator kodawari.swim_bake") for e in entries)
    assert "operator kodawari.swim_apply" in entries
    assert "KODAWARI_PT_swim_add" not in logs


def test_hair_panels_draw(empty_scene):
    _hair_rig(empty_scene)
    logs = showing_panels("KODAWARI_PT_hair")
    entries = _all_entries(logs)
    assert "template_list rods" in entries and "template_list keys" in entries
    assert "template_list colliders" in entries
    assert any(e.startswith("operator kodawari.rod_bake") for e in entries)
    # Lists a user can read: "1 key", a labelled view direction, a labelled Add Rod, "+" on keys.
    labels = [e.name for e in entries if e.kind == "label"]
    assert "1 key" in labels and "1 keys" not in labels
    assert "Ahoge.00" in labels, "the collider row names its bone"
    direction = next(e for e in entries if e == "prop direction")
    assert direction.kwargs.get("text"), "the view-direction ball has a label"
    add_rod = next(e for e in entries if e == "operator kodawari.rod_add")
    assert add_rod.kwargs.get("text") and "Add" in add_rod.kwargs["text"]
    assert "menu KODAWARI_MT_hair_key_add" in entries


def test_gait_panels_draw(empty_scene):
    _gait_horse(empty_scene)
    logs = showing_panels("KODAWARI_PT_gait")
    entries = _all_entries(logs)
    assert "prop speed" in entries
    assert any(e.startswith("operator kodawari.gait_bake") for e in entries)
    assert len(logs) >= 1 + 4 + 5, "rig, table, legs and one sub-panel per gait and per leg"


@pytest.mark.parametrize("prefix", ["KODAWARI_PT_swim", "KODAWARI_PT_hair", "KODAWARI_PT_gait"])
def test_settings_panels_use_split_layout(empty_scene, prefix):
    """Every setting a panel draws has its label split off, with a keyframe decorator."""
    {
        "KODAWARI_PT_swim": lambda: add_swim(make_fish("tuna"), fins=("fin_pectoral",)),
        "KODAWARI_PT_hair": lambda: _hair_rig(empty_scene),
        "KODAWARI_PT_gait": lambda: _gait_horse(empty_scene),
    }[prefix]()
    panels = [p for p in _settings_panels(prefix) if p.poll(bpy.context)]
    assert len(panels) >= 3, "advanced settings are in sub-panels"
    assert any("DEFAULT_CLOSED" in getattr(p, "bl_options", ()) for p in panels), (
        "some sub-panel starts closed"
    )
    for panel in panels:
        props = [e for e in draw_body(panel) if e.kind in ("prop", "prop_search") and not e.in_list]
        unsplit = [e.name for e in props if not e.split]
        assert not unsplit, f"{panel.__name__} draws {unsplit} without use_property_split"


@pytest.mark.parametrize("prefix", ["KODAWARI_PT_swim", "KODAWARI_PT_hair", "KODAWARI_PT_gait"])
def test_panels_hide_for_objects_they_do_not_serve(empty_scene, prefix):
    camera = bpy.data.objects.new("Camera", bpy.data.cameras.new("Camera"))
    empty_scene.collection.objects.link(camera)
    bpy.context.view_layer.objects.active = camera
    for panel in kodawari_classes(prefix):
        assert not panel.poll(bpy.context), f"{panel.__name__} shows on a camera"


def test_feature_panels_hide_on_objects_without_the_feature(empty_scene):
    """A plain armature (a horse without hair, a hair rig without gait, a plain mesh) shows
    no settings panel of a feature it does not use, only that feature's one Add entry."""
    hair_rig = _hair_rig(empty_scene)
    bpy.context.view_layer.objects.active = hair_rig
    assert not [p.__name__ for p in _settings_panels("KODAWARI_PT_gait") if p.poll(bpy.context)]
    assert bpy.types.KODAWARI_PT_gait_add.poll(bpy.context)
    add = draw_body(bpy.types.KODAWARI_PT_gait_add)
    assert [e.name for e in add if e.kind == "operator"] == ["kodawari.gait_setup"]

    gait_horse = _gait_horse(empty_scene)
    bpy.context.view_layer.objects.active = gait_horse
    assert not [p.__name__ for p in _settings_panels("KODAWARI_PT_hair") if p.poll(bpy.context)]
    assert [e.name for e in draw_body(bpy.types.KODAWARI_PT_hair_add) if e.kind == "operator"] == [
        "kodawari.rod_add"
    ]

    mesh = make_fish("tuna")
    bpy.context.view_layer.objects.active = mesh
    assert not [p.__name__ for p in _settings_panels("KODAWARI_PT_swim") if p.poll(bpy.context)]
    assert [e.name for e in draw_body(bpy.types.KODAWARI_PT_swim_add) if e.kind == "operator"] == [
        "kodawari.swim_add"
    ]


def test_sidebar_tab_shows_the_active_creature(empty_scene):
    obj = make_fish("tuna")
    add_swim(obj)
    panel = bpy.types.KODAWARI_PT_sidebar
    assert (
        panel.bl_space_type == "VIEW_3D"
        and panel.bl_region_type == "UI"
        and panel.bl_category == "Kodawari"
    )
    assert panel.poll(bpy.context)
    entries = draw_body(panel)
    assert "prop frequency" in entries and "operator kodawari.swim_bake" in entries
    _gait_horse(empty_scene)
    entries = draw_body(panel)
    assert "prop speed" in entries and "operator kodawari.gait_bake" in entries
    assert "operator kodawari.rod_add" in entries, "the horse can be given hair from the tab"


LABEL_ROOM = (
    12  # columns of text the label side of a split row shows at the default Properties width
)


def _columns(text):
    import unicodedata

    return sum(2 if unicodedata.east_asian_width(c) in "WF" else 1 for c in text)


@pytest.mark.parametrize("prefix", ["KODAWARI_PT_swim", "KODAWARI_PT_hair", "KODAWARI_PT_gait"])
def test_split_labels_fit_the_default_width(empty_scene, prefix):
    """Labels left of a setting are not cut off ("Referenc…"), in English or Japanese.
    The room was measured on screenshots of the real window (blend_samples/ui_screenshots.py):
    "Acceleration" and "Swing Height" fit, "Head Amplitude" and "Reference Bone" were cut."""
    from kodawari.translations import ja

    {
        "KODAWARI_PT_swim": lambda: add_swim(make_fish("tuna"), fins=("fin_pectoral",)),
        "KODAWARI_PT_hair": lambda: _hair_rig(empty_scene),
        "KODAWARI_PT_gait": lambda: _gait_horse(empty_scene),
    }[prefix]()
    too_long = []
    for panel in [p for p in _settings_panels(prefix) if p.poll(bpy.context)]:
        for entry in draw_body(panel):
            if entry.kind not in ("prop", "prop_search") or not entry.split or entry.in_list:
                continue
            rna = entry.kwargs["data"].bl_rna.properties[entry.name]
            if rna.type == "BOOLEAN":
                continue  # a checkbox's text is on the wide side
            label = entry.kwargs.get("text", rna.name)
            for text in (label, ja.STRINGS.get(label, "")):
                if _columns(text) > LABEL_ROOM:
                    too_long.append((panel.__name__, text))
    assert not too_long, f"labels cut off at the default width: {too_long}"
