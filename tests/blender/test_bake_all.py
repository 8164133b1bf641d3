"""Render farms (issue 14): one headless command bakes every creature in a .blend, and the
baked file renders pixel for pixel the same on a Blender without Kodawari, its caches
travelling with the file (relative paths, beside the .blend).

    blender -b shot.blend --python-expr "import kodawari; kodawari.bake_all()"

Each step runs in a fresh Blender process (the program or the bpy module running these
tests): bake, render with the add-on, render without it."""

import os

import bpy
import numpy as np
import pytest
from bake_scenes import hair_rig, swimming_fish
from farm_worker import rendered_pixels, run_blender, run_worker
from fish_helpers import activate, make_fish
from gait_scene import horse
from hair_rig import add_camera

FRAMES = (1, 6, 12)


def _bake_all(blend, cwd):
    if bpy.app.binary_path:  # exactly the documented command
        return run_blender(blend, "--python-expr", "import kodawari; kodawari.bake_all()", cwd=cwd)
    return run_worker("bake", blend, cwd=cwd)


def _shot(scene, path):
    """A fish, a hair rig with something on its hair, and a galloping horse, in one camera."""
    fish = swimming_fish(fins=("fin_dorsal",), frequency=2.0)
    scene.frame_start, scene.frame_end = 1, 12
    fish.location = (0.0, 0.0, 1.0)
    rig = hair_rig(scene, ((1, 0.0), (6, 0.4), (12, -0.3)))
    rig.location = (-2.5, 0.0, 0.0)
    bead = bpy.data.objects.new("bead", bpy.data.meshes.new("bead"))
    bead.data.from_pydata(
        [(x, y, z) for x in (-0.15, 0.15) for y in (-0.15, 0.15) for z in (-0.15, 0.15)],
        [],
        [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)],
    )
    scene.collection.objects.link(bead)
    bead.parent, bead.parent_type, bead.parent_bone = rig, "BONE", "Ahoge.04"
    gait = horse(scene, [(1, 3.0), (12, 3.0)])
    gait.location = (2.5, 0.0, 0.0)
    add_camera(scene, "Camera", (0.0, -14.0, 2.0), look_at=(0.0, 0.0, 1.0))
    activate(fish)
    bpy.ops.wm.save_as_mainfile(filepath=path)


def test_a_baked_shot_renders_the_same_without_the_addon(empty_scene, tmp_path):
    shot = tmp_path / "shots" / "shot_010.blend"
    shot.parent.mkdir()
    _shot(empty_scene, str(shot))
    elsewhere = tmp_path / "worker"  # the farm's working folder is not the .blend's
    elsewhere.mkdir()
    code, output = _bake_all(str(shot), cwd=elsewhere)
    assert code == 0, output
    assert "3 baked, 0 failed" in output, output
    cache = shot.parent / "blendcache_shot_010" / "tuna_swim.pc2"
    assert cache.is_file(), output

    # The farm copies the shot and its cache folder somewhere else: they travel together.
    farm = tmp_path / "farm"
    farm.mkdir()
    for name in ("shot_010.blend", "blendcache_shot_010"):
        os.rename(shot.parent / name, farm / name)
    images = {}
    for addon in ("addon", "no-addon"):
        out = tmp_path / addon
        code, output = run_worker(
            "render",
            str(farm / "shot_010.blend"),
            str(out),
            addon,
            *map(str, FRAMES),
            cwd=elsewhere,
        )
        assert code == 0, output
        images[addon] = [rendered_pixels(str(out / f"{frame:04d}.png")) for frame in FRAMES]
    for frame, with_addon, without in zip(FRAMES, images["addon"], images["no-addon"]):
        assert np.array_equal(with_addon, without), f"frame {frame} differs without the add-on"
    first, *others = images["no-addon"]
    assert all(np.abs(first - other).max() > 0 for other in others), "nothing moves in the renders"


def test_the_farm_command_exits_non_zero_when_a_creature_fails(empty_scene, tmp_path):
    swimming_fish("broken", fins=("fin_dorsal",))
    broken = bpy.data.objects["broken"]
    broken.vertex_groups.remove(broken.vertex_groups["fin_dorsal"])
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "shot.blend"))
    code, output = _bake_all(str(tmp_path / "shot.blend"), cwd=tmp_path)
    assert code != 0, output
    assert "FAILED" in output and "broken" in output and "fin_dorsal" in output, output


def test_bake_all_says_which_creature_failed_and_bakes_the_others(empty_scene, tmp_path):
    import kodawari
    from kodawari.bake_job import BakeError

    swimming_fish("broken", fins=("fin_dorsal",))
    swimming_fish("healthy")
    empty_scene.frame_start, empty_scene.frame_end = 1, 6
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "shot.blend"))
    broken = bpy.data.objects["broken"]
    broken.vertex_groups.remove(broken.vertex_groups["fin_dorsal"])
    from kodawari.fish import runtime

    runtime.forget()
    with pytest.raises(BakeError, match="broken.*fin_dorsal"):
        kodawari.bake_all(exit_on_failure=False)
    healthy = bpy.data.objects["healthy"]
    assert healthy.kodawari_swim.baked == "MESH_CACHE"
    assert bpy.data.objects["broken"].kodawari_swim.baked == "NONE"
    # A cache that did not travel with the file is a failure too, not a frozen fish.
    os.remove(bpy.path.abspath(healthy.modifiers["Kodawari Swim Cache"].filepath))
    bpy.data.objects.remove(bpy.data.objects["broken"])
    with pytest.raises(BakeError, match="healthy.*cache .* is missing"):
        kodawari.bake_all(exit_on_failure=False)


def test_bake_all_of_an_unsaved_file_asks_to_save(empty_scene):
    import kodawari
    from kodawari.bake_job import BakeError

    make_fish("tuna")
    with pytest.raises(BakeError, match="Save the file first"):
        kodawari.bake_all(exit_on_failure=False)
