"""Every setting and operator says in plain words what it does, and shows its unit.

The strings are walked from the registered classes' RNA (kodawari.translations.strings),
so a setting added later without a tooltip fails here."""

import re


def _strings():
    from kodawari.translations import strings

    found = strings.registered()
    assert len(found) > 200, "the walk found the add-on's settings and operators"
    return found


def test_every_property_and_operator_has_a_tooltip(addon):
    empty = [s for s in _strings() if s.field.endswith("description") and not s.text.strip()]
    assert not empty, f"{len(empty)} without a tooltip: {empty[:20]}"


def test_no_tooltip_talks_to_developers(addon):
    jargon = re.compile(r"\bseeds?\b|\bCCD\b|\bLF\b|\bLH\b|\bRH\b|\^|²|v²|\bD[12]\b", re.IGNORECASE)
    bad = [s for s in _strings() if s.field.endswith("description") and jargon.search(s.text)]
    assert not bad, f"tooltips in developers' words: {bad}"


def test_names_are_readable(addon):
    labels = [s for s in _strings() if s.field.endswith("name") or s.field == "label"]
    raw = [s for s in labels if re.fullmatch(r"[A-Z0-9_]{3,}", s.text) or "_" in s.text]
    assert not raw, f"raw identifiers shown as names: {raw}"


def _prop(owner, name):
    return owner.bl_rna.properties[name]


def test_units_show(addon):
    """Angles in degrees, lengths and speeds with units, fractions as sliders (issue 14 item 4)."""
    from kodawari.fish.props import KodawariSwimFin as fin
    from kodawari.fish.props import KodawariSwimSettings as swim
    from kodawari.gait.props import KodawariGaitBone as bone
    from kodawari.gait.props import KodawariGaitEntry as entry
    from kodawari.gait.props import KodawariGaitSettings as gait
    from kodawari.hair.props import KodawariHairRod as hair_rod

    assert _prop(fin, "amplitude").subtype == "ANGLE", "fin amplitude is an angle, like phase lag"
    assert _prop(fin, "phase_lag").subtype == "ANGLE"
    assert _prop(swim, "amplitude_head").subtype == "FACTOR", "head amplitude shows three decimals"
    assert _prop(gait, "acceleration").unit == "ACCELERATION"
    assert _prop(gait, "speed").unit == "VELOCITY"
    assert (
        _prop(entry, "swing_height").subtype == "DISTANCE"
        and _prop(entry, "swing_height").unit == "LENGTH"
    )
    assert _prop(entry, "swing_time").unit in {"TIME", "TIME_ABSOLUTE"}
    assert _prop(entry, "duty_factor").subtype == "FACTOR"
    assert "°" in _prop(bone, "limit_min").name and "°" in _prop(bone, "limit_max").name, (
        "joint limits (stored in degrees) say so"
    )
    assert _prop(hair_rod, "stiffness").subtype == "FACTOR"
    assert _prop(hair_rod, "wind").unit == "VELOCITY"
