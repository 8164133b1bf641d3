"""Speed modes that are physical (issue 10 items 5 and 7), measured on the mesh: the
tail's peak-to-peak excursion and how far the object travels per second."""

import bpy
import numpy as np
import pytest
from fish_helpers import FIN_KIND, add_swim, body_length, frames, make_fish, rest, set_fps

BODY = [
    ("eel", "ANGUILLIFORM"),
    ("tuna", "CARANGIFORM"),
    ("tuna", "THUNNIFORM"),
    ("dolphin", "CETACEAN"),
]
FINS = [("boxfish", "OSTRACIIFORM"), ("filefish", "BALISTIFORM"), ("pufferfish", "LABRIFORM")]
FPS = 24


def _tail_peak_to_peak(obj, axis, frequency):
    beat = round(FPS / frequency)
    tail = int(np.argmin(rest(obj)[:, 0]))
    return float(np.ptp(frames(obj, range(1, beat + 1))[:, tail, axis]))


def _speed(obj, seconds=2):
    scene = bpy.context.scene
    scene.frame_set(1)
    start = np.array(obj.delta_location)
    scene.frame_set(1 + seconds * FPS)
    return float(np.linalg.norm(np.array(obj.delta_location) - start)) / seconds


@pytest.mark.parametrize("mode", ["BAINBRIDGE", "STROUHAL"])
@pytest.mark.parametrize("kind,preset", BODY)
def test_body_swimmers_travel_at_strouhal_two_to_four_tenths(empty_scene, kind, preset, mode):
    set_fps(FPS)
    obj = make_fish(kind)
    settings = add_swim(obj, head_axis="POS_X", preset=preset)
    axis = 2 if settings.bend == "DORSOVENTRAL" else 1
    peak_to_peak = _tail_peak_to_peak(obj, axis, settings.frequency)
    settings.speed_mode = mode
    speed = _speed(obj)
    strouhal = settings.frequency * peak_to_peak / speed
    assert 0.2 <= strouhal <= 0.4, (strouhal, speed, peak_to_peak)


@pytest.mark.parametrize("kind,preset", BODY)
def test_presets_default_to_cruise_amplitude_and_reach_the_maximum(empty_scene, kind, preset):
    set_fps(FPS)
    obj = make_fish(kind)
    settings = add_swim(obj, head_axis="POS_X", preset=preset)
    axis = 2 if settings.bend == "DORSOVENTRAL" else 1
    length = body_length(obj)
    cruise = _tail_peak_to_peak(obj, axis, settings.frequency) / length
    assert 0.09 <= cruise <= 0.14, cruise  # cruising fish: 0.1-0.13 L peak-to-peak
    settings.amplitude = 0.1  # Bainbridge's maximum, L/5 peak-to-peak
    assert _tail_peak_to_peak(obj, axis, settings.frequency) / length >= 0.18


@pytest.mark.parametrize("mode", ["BAINBRIDGE", "STROUHAL"])
@pytest.mark.parametrize("kind,preset", FINS)
def test_fin_swimmers_move_forward_at_half_a_length_per_beat(empty_scene, kind, preset, mode):
    set_fps(FPS)
    obj = make_fish(kind)
    fins = tuple(g.name for g in obj.vertex_groups if g.name in FIN_KIND)
    settings = add_swim(obj, fins=fins, head_axis="POS_X", preset=preset)
    settings.speed_mode = mode
    speed = _speed(obj)
    forward = np.array(obj.delta_location) @ np.array((1.0, 0.0, 0.0))
    assert forward > 0
    assert speed == pytest.approx(0.5 * settings.frequency * body_length(obj), rel=0.02)
