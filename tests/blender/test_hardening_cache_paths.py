"""Fish caches never get lost or overwritten (issue 11 items 4, 5, 7): beside the saved
.blend in `blendcache_<file name>/`, one name per object, an unsaved file asks to be
saved first, and a path that cannot be written is refused before any frame is baked,
with no stray `.part` left behind."""

import os

import bpy
import numpy as np
import pytest
from bake_scenes import swimming_fish
from fish_helpers import activate, evaluated


def _fish(name="tuna", frequency=1.0):
    return swimming_fish(name, frequency=frequency)


def _refused(words, **kwargs):
    with pytest.raises(RuntimeError) as info:
        bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6, **kwargs)
    message = str(info.value)
    assert "Traceback" not in message, message
    for word in words:
        assert word.lower() in message.lower(), message
    return message


def _unbaked(obj, frame=1):
    assert obj.kodawari_swim.baked == "NONE"
    assert not [m for m in obj.modifiers if m.type == "MESH_CACHE"]
    assert bpy.context.scene.frame_current == frame


def test_an_unsaved_file_is_asked_to_save_first(empty_scene, tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    obj = _fish()
    _refused(["save the file first"])
    _refused(["save the file first"], filepath="//tuna.pc2")
    _unbaked(obj)
    assert os.listdir(tmp_path) == []
    assert not [f for f in os.listdir(bpy.app.tempdir) if f.endswith((".pc2", ".part"))]


def test_caches_go_beside_the_blend_in_a_folder_named_after_it(empty_scene, tmp_path):
    obj = _fish()
    path = str(tmp_path / "shot_010.blend")
    bpy.ops.wm.save_as_mainfile(filepath=path)
    obj = bpy.data.objects["tuna"]
    activate(obj)
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6) == {"FINISHED"}
    modifier = obj.modifiers["Kodawari Swim Cache"]
    assert modifier.filepath == "//blendcache_shot_010/tuna_swim.pc2"
    assert os.path.isfile(tmp_path / "blendcache_shot_010" / "tuna_swim.pc2")
    assert not list(tmp_path.rglob("*.part"))


def test_two_files_in_one_folder_keep_their_own_fish(empty_scene, tmp_path):
    """Each shot has a fish called 'tuna'; reopened, shot 1 still plays shot 1's swim."""
    played = {}
    for shot, frequency in (("shot_1", 1.0), ("shot_2", 3.0)):
        bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
        obj = _fish("tuna", frequency)
        bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / f"{shot}.blend"))
        obj = bpy.data.objects["tuna"]
        activate(obj)
        assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6) == {"FINISHED"}
        bpy.context.scene.frame_set(4)
        played[shot] = evaluated(obj)
        bpy.ops.wm.save_mainfile()
    assert np.abs(played["shot_1"] - played["shot_2"]).max() > 1e-3  # the shots differ
    for shot in ("shot_1", "shot_2"):
        bpy.ops.wm.open_mainfile(filepath=str(tmp_path / f"{shot}.blend"))
        bpy.context.scene.frame_set(4)
        np.testing.assert_array_equal(evaluated(bpy.data.objects["tuna"]), played[shot])


def test_objects_whose_names_clean_alike_get_their_own_files(empty_scene, tmp_path):
    _fish("tuna.001")
    _fish("tuna_001")
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "shot.blend"))
    paths = []
    for name in ("tuna.001", "tuna_001"):
        obj = bpy.data.objects[name]
        activate(obj)
        assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6) == {"FINISHED"}
        paths.append(bpy.path.abspath(obj.modifiers["Kodawari Swim Cache"].filepath))
    assert len(set(paths)) == 2 and all(os.path.isfile(p) for p in paths)


def test_another_objects_cache_is_not_overwritten(empty_scene, tmp_path):
    cache = str(tmp_path / "shared.pc2")
    first = _fish("first")
    assert bpy.ops.kodawari.swim_bake(frame_start=1, frame_end=6, filepath=cache) == {"FINISHED"}
    size = os.path.getsize(cache)
    second = _fish("second")
    activate(second)
    _refused(["cache of 'first'"], filepath=cache)
    _unbaked(second)
    assert os.path.getsize(cache) == size and first.kodawari_swim.baked == "MESH_CACHE"


@pytest.mark.parametrize("case", ["folder", "under_a_file", "read_only"])
def test_a_path_that_cannot_be_written_is_refused_before_baking(empty_scene, tmp_path, case):
    obj = _fish()
    if case == "folder":
        (tmp_path / "caches").mkdir()
        path, words = str(tmp_path / "caches"), ["is a folder"]
    elif case == "under_a_file":
        (tmp_path / "notes.txt").write_text("not a folder")
        path, words = str(tmp_path / "notes.txt" / "tuna.pc2"), ["is a file, not a folder"]
    else:
        # /sys refuses new files even to root (a chmod'ed folder would not stop root).
        path, words = "/sys/kodawari_test_tuna.pc2", ["cannot write", "permission denied"]
    _refused(words, filepath=path)
    _unbaked(obj)
    assert not list(tmp_path.rglob("*.part")) and not os.path.exists(path + ".part")
