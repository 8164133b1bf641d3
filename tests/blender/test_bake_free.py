"""Free Bake (issue 14 item 7): a baked fish goes back to swimming live with its whole
setup (fins, preset, bend, timing), as Blender's Cloth "Free Bake" keeps the cloth."""

import os

import bpy
import numpy as np
import pytest
from fish_helpers import activate, add_swim, evaluated, frames, make_fish, set_fps


def _setup():
    set_fps(24)
    obj = make_fish("tuna")
    settings = add_swim(
        obj, fins=("fin_dorsal", "fin_pectoral"), head_axis="POS_X", preset="THUNNIFORM"
    )
    settings.bend = "DORSOVENTRAL"
    settings.frequency = 2.5
    settings.speed_mode = "BAINBRIDGE"
    return obj, settings


def _setup_of(settings):
    return (
        [(f.vertex_group, f.kind, f.amplitude) for f in settings.fins],
        settings.preset,
        settings.bend,
        settings.frequency,
        settings.speed_mode,
        settings.head_axis,
    )


def _key_names(obj):
    keys = obj.data.shape_keys
    return [k.name for k in keys.key_blocks] if keys is not None else []


@pytest.mark.parametrize("target", ["MESH_CACHE", "SHAPE_KEYS"])
def test_free_bake_keeps_the_setup_and_swims_live_again(empty_scene, tmp_path, target):
    obj, settings = _setup()
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "shot.blend"))
    obj = bpy.data.objects["tuna"]
    settings = obj.kodawari_swim
    activate(obj)
    live = frames(obj, range(1, 7))
    setup = _setup_of(settings)
    keys_before = _key_names(obj)
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6, target=target) == {"FINISHED"}
    cache = bpy.path.abspath(settings.cache_path) if target == "MESH_CACHE" else None
    assert cache is None or os.path.isfile(cache)

    assert bpy.ops.kodawari.swim_free_bake() == {"FINISHED"}
    assert settings.baked == "NONE" and _setup_of(settings) == setup
    assert not [m for m in obj.modifiers if m.type == "MESH_CACHE"]
    assert _key_names(obj) == keys_before  # no baked keys left (nor the Basis they needed)
    assert cache is None or not os.path.exists(cache)  # its own cache file is freed too
    # Live again: the same motion as before the bake, and settings act at once.
    np.testing.assert_allclose(frames(obj, range(1, 7)), live, atol=1e-5)
    settings.frequency = 1.0
    bpy.context.scene.frame_set(5)
    assert np.abs(evaluated(obj) - live[4]).max() > 1e-4
    # And it bakes again.
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6, target=target) == {"FINISHED"}


def test_free_bake_on_a_fish_that_is_not_baked_is_refused(empty_scene):
    _obj, settings = _setup()
    with pytest.raises(RuntimeError, match="baked swim"):
        bpy.ops.kodawari.swim_free_bake()
    assert settings.enabled and settings.baked == "NONE"
