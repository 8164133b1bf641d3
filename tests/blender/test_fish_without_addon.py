"""A live (unbaked) fish opened on a Blender without Kodawari: the Fish Swim modifier still
evaluates from the frame table saved with the file, so the fish shows the pose of the frame
it was saved on at every frame (it cannot swim without the add-on: README, "What export and render keep"), and
saving it there loses nothing: back with the add-on it swims exactly as before.

Each step runs in a fresh Blender process (the program or the bpy module running these tests)."""

import bpy
import numpy as np
from bake_scenes import swimming_fish
from farm_worker import rendered_pixels, run_worker
from fish_helpers import activate
from hair_rig import add_camera

FRAMES = (1, 6, 12)
SAVED_ON = 6


def _render(blend, out, addon, cwd):
    code, output = run_worker("render", str(blend), str(out), addon, *map(str, FRAMES), cwd=cwd)
    assert code == 0, output
    return {frame: rendered_pixels(str(out / f"{frame:04d}.png")) for frame in FRAMES}


def test_a_live_fish_keeps_its_saved_pose_without_the_addon_and_swims_again_with_it(
    empty_scene, tmp_path
):
    fish = swimming_fish(frequency=2.0)
    fish.location = (0.0, 0.0, 1.0)
    empty_scene.frame_start, empty_scene.frame_end = 1, 12
    add_camera(empty_scene, "Camera", (0.0, 0.0, 3.0), look_at=(0.0, 0.0, 1.0))  # from above
    activate(fish)
    empty_scene.frame_set(SAVED_ON)
    shot = tmp_path / "shot.blend"
    bpy.ops.wm.save_as_mainfile(filepath=str(shot))

    live = _render(shot, tmp_path / "addon", "addon", cwd=tmp_path)
    assert all(np.abs(live[1] - live[f]).max() > 0 for f in FRAMES[1:]), "it swims"

    frozen = _render(shot, tmp_path / "no-addon", "no-addon", cwd=tmp_path)
    background = frozen[1][:4]  # the top-left pixel: the world behind the fish
    drawn = np.abs(frozen[1].reshape(-1, 4) - background).max(axis=1) > 0.05
    assert drawn.mean() > 0.02, "the fish is drawn (not lost, not collapsed)"
    for frame in FRAMES:
        assert np.array_equal(frozen[frame], live[SAVED_ON]), (
            f"frame {frame} without the add-on shows the pose saved on frame {SAVED_ON}"
        )

    # Opened and saved again on another frame by that Blender: the swim comes back whole.
    code, output = run_worker("resave", str(shot), "12", cwd=tmp_path)
    assert code == 0, output
    again = _render(shot, tmp_path / "addon-again", "addon", cwd=tmp_path)
    for frame in FRAMES:
        assert np.array_equal(again[frame], live[frame]), f"frame {frame} swims as before"
