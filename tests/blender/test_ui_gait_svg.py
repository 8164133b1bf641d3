"""The gait report's picture a user can read and zoom: an SVG with real text, axes
with units, a legend, one curve per foot and the footfall bars of the bake."""

import xml.etree.ElementTree as ET

import bpy
import numpy as np
from gait_scene import horse

SVG = "{http://www.w3.org/2000/svg}"


def test_gait_report_writes_a_labelled_svg(empty_scene, tmp_path):
    from kodawari.gait import runtime

    rig = horse(empty_scene, [(1, 1.5), (40, 1.5), (120, 8.0)])
    assert bpy.ops.kodawari.gait_bake(frame_start=1, frame_end=120) == {"FINISHED"}
    assert bpy.ops.kodawari.gait_report(filepath=str(tmp_path / "report.png")) == {"FINISHED"}
    root = ET.parse(tmp_path / "report.svg").getroot()
    assert root.tag == f"{SVG}svg" and root.get("viewBox"), "a scalable picture"
    texts = [t.text for t in root.iter(f"{SVG}text")]
    assert "Time (s)" in texts and any(t.startswith("Fore-aft position (m)") for t in texts), (
        "axes with units"
    )
    assert {"Left fore", "Right fore", "Left hind", "Right hind"} <= set(texts), (
        "legend and rows name the feet"
    )
    assert "Walk" in texts and "Planted" in texts
    curves = [
        p
        for p in root.iter(f"{SVG}polyline")
        if p.get("stroke-dasharray") is None and len(p.get("points").split()) > 100
    ]
    assert len(curves) == 4, "one fore-aft curve per foot, every frame"
    # The footfall bars are the bake's planted runs: count them against the contact channels.
    contacts = runtime.last_bake(rig)["result"]["contacts"] > 0.5
    planted_runs = sum(
        int(np.sum(np.diff(np.concatenate([[0], c.astype(int), [0]])) == 1)) for c in contacts.T
    )
    bars = [
        r
        for r in root.iter(f"{SVG}rect")
        if r.get("fill") == "#1a1a1a" and float(r.get("height")) == 16
    ]
    assert len(bars) == planted_runs
