"""Live hair against the timeline (issue 9 items 3-5): a jump gives the pose playback gives,
a render writes what playback writes, and a cache thinned by its budget scrubs back exactly."""

import bpy
import numpy as np
from hair_rig import ahoge_under_a_moving_head, rotations


def _runtime(obj):
    from kodawari.hair import runtime

    return runtime.get(obj)


def _play(scene, obj, first, last):
    poses = {}
    for frame in range(first, last + 1):
        scene.frame_set(frame)
        poses[frame] = rotations(obj, "Ahoge")
    return poses


def _restart(obj):
    from kodawari.hair import runtime

    runtime.invalidate(obj)


def test_a_jump_in_the_timeline_gives_the_pose_playing_to_that_frame_gives(empty_scene):
    obj = ahoge_under_a_moving_head(empty_scene)
    played = _play(empty_scene, obj, 1, 30)
    _restart(obj)
    empty_scene.frame_set(1)
    empty_scene.frame_set(30)  # a jump: frames 2-29 never shown
    np.testing.assert_allclose(rotations(obj, "Ahoge"), played[30], atol=1e-6)
    # Nothing was cached that playback would not produce.
    rt = _runtime(obj)
    for frame in (2, 15, 29):
        np.testing.assert_allclose(rt.cached_rotations(frame), played[frame], atol=1e-6)
    # A jump back inside the cache, then forward past it, too.
    empty_scene.frame_set(12)
    np.testing.assert_allclose(rotations(obj, "Ahoge"), played[12], atol=1e-6)
    empty_scene.frame_set(40)
    later = rotations(obj, "Ahoge")
    _restart(obj)
    assert np.allclose(_play(empty_scene, obj, 1, 40)[40], later, atol=1e-6)


def test_scrubbing_back_into_frames_the_budget_dropped_is_exact(empty_scene):
    obj = ahoge_under_a_moving_head(empty_scene)
    empty_scene.frame_set(1)
    rt = _runtime(obj)
    rt.system.cache_budget = 12 * rt.system.cache_bytes  # room for about a dozen frames
    played = _play(empty_scene, obj, 1, 40)
    assert rt.system.cache_bytes <= rt.system.cache_budget
    dropped = [f for f in range(2, 30) if f not in rt.cached_frames]
    assert dropped, "the budget should have thinned the cache"
    for frame in (dropped[-1], dropped[0], dropped[len(dropped) // 2]):
        empty_scene.frame_set(frame)
        np.testing.assert_array_equal(rotations(obj, "Ahoge"), played[frame])


def test_rendering_the_animation_writes_the_rotations_playback_writes(empty_scene, tmp_path):
    obj = ahoge_under_a_moving_head(empty_scene)
    scene = empty_scene
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = scene.render.resolution_y = 16
    scene.render.resolution_percentage = 100
    scene.render.image_settings.file_format = "PNG"
    scene.render.filepath = str(tmp_path / "frame_")
    scene.frame_start, scene.frame_end = 1, 12
    rendered = {}

    def record(scene, depsgraph=None):
        rendered[scene.frame_current] = _runtime(obj).cached_rotations(scene.frame_current)

    bpy.app.handlers.frame_change_post.append(record)  # after the add-on's own handler
    try:
        bpy.ops.render.render(animation=True)
    finally:
        bpy.app.handlers.frame_change_post.remove(record)
    assert sorted(rendered) == list(range(1, 13))
    _restart(obj)
    played = _play(scene, obj, 1, 12)
    for frame in range(1, 13):
        np.testing.assert_allclose(
            rendered[frame], played[frame], atol=1e-6, err_msg=f"frame {frame}"
        )
    assert np.abs(played[12] - played[1]).max() > 0.01, "the head's motion should swing the chain"
