"""Fin motion fades into the body over the fin's root (issue 10 item 2): on smooth
welded fish, no mesh edge stretches past 1.5x at any frame, for every fin motion."""

import bpy
import numpy as np
import pytest
from fish_helpers import activate, frames, group_mask, rest, set_fps, smooth_fish

MOTIONS = ("FLAP", "UP_DOWN", "TWIST", "UNDULATE")
# Strong but ordinary settings: the panel's soft maximum is 1.5 rad; 0.6 rad is a big beat.
AMPLITUDE = {"FLAP": 0.6, "UP_DOWN": 0.6, "TWIST": 0.6, "UNDULATE": 0.3}


def _edges(obj):
    edges = np.empty((len(obj.data.edges), 2), dtype=np.int32)
    obj.data.edges.foreach_get("vertices", edges.reshape(-1))
    return edges


def _swing(still, moving, mask, rest):
    """The fin's largest move over the frames (beside the same frames with the fins
    still) as a share of its height (how far its vertices stand from the body)."""
    from kodawari import native

    height = native.module().swim_nearest_distances(rest[mask], rest[~mask]).max()
    return float(np.linalg.norm(moving[:, mask] - still[:, mask], axis=2).max() / height)


def _max_stretch(rest, positions, edges):
    before = np.linalg.norm(rest[edges[:, 0]] - rest[edges[:, 1]], axis=1)
    after = np.linalg.norm(positions[:, edges[:, 0]] - positions[:, edges[:, 1]], axis=2)
    return float((after / np.maximum(before, 1e-12)).max())


# The shapes: goldfish (deep), dolphin (cetacean, flukes), shark; and a tuna
# (spindle), a flat catfish-like and an eel: smooth (subdivided twice) and low-poly.
@pytest.mark.parametrize("form", ["spindle", "cetacean", "deep", "shark", "flat", "eel"])
@pytest.mark.parametrize("subdivisions", [2, 0])
def test_no_edge_stretches_past_one_and_a_half_for_any_fin_motion(empty_scene, form, subdivisions):
    set_fps(24)
    obj = smooth_fish.build_smooth_fish(form, subdivisions=subdivisions)
    for group in list(obj.vertex_groups):
        obj.vertex_groups.remove(group)
    activate(obj)
    preset = "CETACEAN" if form == "cetacean" else "CARANGIFORM"
    assert bpy.ops.kodawari.swim_add(head_axis="POS_X", preset=preset, frequency=2.0) == {
        "FINISHED"
    }
    assert bpy.ops.kodawari.swim_fin_find() == {"FINISHED"}
    settings = obj.kodawari_swim
    assert len(settings.fins) >= 3
    co = rest(obj)
    edges = _edges(obj)
    masks = {fin.vertex_group: group_mask(obj, fin.vertex_group) for fin in settings.fins}
    for fin in settings.fins:
        fin.amplitude = 0.0
        fin.feathering = 0.0
    still = frames(obj, range(1, 13))
    worst, swing = {}, {}
    for motion in MOTIONS:
        for fin in settings.fins:
            fin.motion = motion
            fin.amplitude = AMPLITUDE[motion]
            fin.feathering = 0.5 if motion == "FLAP" else 0.0
        moving = frames(obj, range(1, 13))
        worst[motion] = _max_stretch(co, moving, edges)
        swing[motion] = [_swing(still, moving, m, co) for m in masks.values()]
    assert max(worst.values()) <= 1.5, worst
    # ... and every fin still beats (not held still to keep its edges short): a swing of
    # 0.6 rad rigid about the root moves the rim by 0.59 of the fin's height; measured
    # 0.14-1.3 here, the smallest the same as before the fade was squashed (§2.4).
    assert min(swing["FLAP"] + swing["UP_DOWN"]) >= 0.1, swing
