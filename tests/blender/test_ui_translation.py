"""Japanese UI: every registered UI string has a translation, and with the interface
switched to Japanese the panels draw Japanese text (labels, setting names, buttons).

Coverage is checked by walking the registered classes' RNA and the panels' literal
texts (kodawari.translations.msgids), so strings added later are caught too."""

import bpy
import pytest
from bpy.app.translations import pgettext_iface
from fish_helpers import add_swim, make_fish
from test_panels_draw import _gait_horse, _hair_rig
from ui_recording import draw_panel, kodawari_classes

SAME_IN_JAPANESE = {"Kodawari", "+X", "-X", "+Y", "-Y", "+Z", "-Z"}


def test_japanese_covers_every_registered_ui_string(addon):
    from kodawari import translations

    assert len(translations.msgids()) > 300
    missing = translations.missing("ja_JP")
    assert not missing, f"{len(missing)} UI strings without Japanese: {missing[:30]}"


@pytest.fixture
def japanese(addon):
    if not bpy.app.build_options.international:
        pytest.skip(
            "this Blender build has no translation support (bpy module built without international)"
        )
    view = bpy.context.preferences.view
    saved = (view.language, view.use_translate_interface, view.use_translate_tooltips)
    view.language = "ja_JP"
    view.use_translate_interface = True
    view.use_translate_tooltips = True
    yield
    view.language, view.use_translate_interface, view.use_translate_tooltips = saved


def _drawn_texts(panel):
    """What Blender would print on screen for one panel: (English, translation context)."""
    texts = [(panel.bl_label, "*")] if "HIDE_HEADER" not in getattr(panel, "bl_options", ()) else []
    for entry in draw_panel(panel):
        if entry.kwargs.get("translate") is False or entry.in_list:
            continue
        text = entry.kwargs.get("text")
        if text == "":
            continue
        if entry.kind == "label" and text:
            texts.append((text, "*"))
        elif entry.kind == "operator":
            if text is None:
                module, name = entry.name.split(".")
                texts.append(
                    (getattr(getattr(bpy.ops, module), name).get_rna_type().name, "Operator")
                )
            else:
                texts.append((text, "*"))
        elif entry.kind in ("prop", "prop_search"):
            texts.append((text or entry.kwargs["data"].bl_rna.properties[entry.name].name, "*"))
    return texts


@pytest.mark.parametrize("prefix", ["KODAWARI_PT_swim", "KODAWARI_PT_hair", "KODAWARI_PT_gait"])
def test_panels_draw_japanese(empty_scene, japanese, prefix):
    {
        "KODAWARI_PT_swim": lambda: add_swim(make_fish("tuna"), fins=("fin_pectoral",)),
        "KODAWARI_PT_hair": lambda: _hair_rig(empty_scene),
        "KODAWARI_PT_gait": lambda: _gait_horse(empty_scene),
    }[prefix]()
    panels = [p for p in kodawari_classes(prefix) if p.poll(bpy.context)]
    texts = [t for p in panels for t in _drawn_texts(p)]
    assert len(texts) > 10
    english = [
        text
        for text, context in texts
        if text not in SAME_IN_JAPANESE and pgettext_iface(text, context) == text
    ]
    assert not english, f"drawn untranslated: {english}"
    assert pgettext_iface("Fish Swim") == "魚の泳ぎ"
    assert pgettext_iface("Add Fish Swim", "Operator") == "魚の泳ぎを追加"


def test_tooltips_translate(japanese):
    from bpy.app.translations import pgettext_tip

    rna = bpy.ops.kodawari.swim_add.get_rna_type()
    assert pgettext_tip(rna.description) != rna.description
    from kodawari.fish.props import KodawariSwimSettings

    description = KodawariSwimSettings.bl_rna.properties["frequency"].description
    assert pgettext_tip(description) == "1秒あたりの尾の振り回数"


def test_reports_translate(empty_scene, japanese):
    """An operator's message in the report area is in Japanese too (Apply Fish Swim's refusal)."""
    make_fish("tuna")
    with pytest.raises(RuntimeError, match="適用する魚の泳ぎがありません"):
        bpy.ops.kodawari.swim_apply()


def test_bake_and_remove_reports_translate(empty_scene, japanese, tmp_path):
    """Reports built from a msgid with variable parts (tip_(...).format) and the bake's
    refusals (BakeError) reach the report area in Japanese, names filled in."""
    obj = make_fish("tuna")
    with pytest.raises(RuntimeError, match=f"'{obj.name}' には削除する魚の泳ぎがありません"):
        bpy.ops.kodawari.swim_remove()
    add_swim(obj, head_axis="POS_X")
    with pytest.raises(RuntimeError, match="終了フレーム 3 が開始フレーム 10 より前です"):
        bpy.ops.kodawari.swim_bake(frame_start=10, frame_end=3, filepath=str(tmp_path / "x.pc2"))
