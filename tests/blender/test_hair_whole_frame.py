"""What one frame of live hair asks of Blender (issue 13 item 2, docs/algorithms.md §3.7).

Blender evaluates a frame, then runs frame_change_post; a pose written there needs a second,
full evaluation of the armature. A frame the cache already holds is written before the
evaluation instead, so the first evaluation is already right: every frame_change_post handler
(another add-on, a render engine, a script) sees the final pose, and Blender evaluates once."""

import bpy
import numpy as np
from hair_rig import (
    add_camera,
    ahoge_under_a_moving_head,
    chain_bones,
    make_rig,
    rotations,
    select_only,
)


def _falling(scene):
    """Nothing animated: a chain sticking out sideways falls and swings under gravity alone, so
    a frame change gives Blender no reason to evaluate the pose again."""
    obj = make_rig(scene, chains=(("Ahoge", (0.0, 0.0, 1.8), (1.0, 0.0, 0.0), 5),))
    select_only(obj, {"Ahoge.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    obj.kodawari_hair.rods[0].stiffness = 0.05
    add_camera(scene, "Front", (0, -4, 1.7))
    scene.frame_start, scene.frame_end = 1, 40
    return obj


def _tips(obj, depsgraph):
    """World positions of the chain's bone tails as Blender evaluated them."""
    evaluated = obj.evaluated_get(depsgraph)
    world = np.array(evaluated.matrix_world)
    tails = np.array(
        [tuple(evaluated.pose.bones[pb.name].tail) + (1.0,) for pb in chain_bones(obj, "Ahoge")]
    )
    return (tails @ world.T)[:, :3]


class _FirstEvaluation:
    """Records, after the add-on's own frame_change_post handler, the pose Blender's first
    evaluation of the frame made (before any second evaluation the add-on's write asks for)."""

    def __init__(self, obj):
        self.obj, self.tips = obj, {}

    def __call__(self, scene, depsgraph=None):
        self.tips[scene.frame_current] = _tips(self.obj, depsgraph)


def test_a_cached_frame_is_right_after_the_first_evaluation(empty_scene):
    scene = empty_scene
    obj = ahoge_under_a_moving_head(scene)
    played = {}
    for frame in range(1, 31):
        scene.frame_set(frame)
        played[frame] = (rotations(obj, "Ahoge"), _tips(obj, bpy.context.evaluated_depsgraph_get()))
    assert np.abs(played[30][1] - played[1][1]).max() > 0.05, (
        "the head's motion should move the chain"
    )
    first = _FirstEvaluation(obj)
    bpy.app.handlers.frame_change_post.append(first)  # after the add-on's handler
    try:
        for frame in (12, 13, 14, 25, 3):  # scrubbing back and playing on inside the cache
            scene.frame_set(frame)
            final = _tips(obj, bpy.context.evaluated_depsgraph_get())
            np.testing.assert_array_equal(rotations(obj, "Ahoge"), played[frame][0])
            np.testing.assert_allclose(final, played[frame][1], atol=1e-6, err_msg=f"frame {frame}")
            # The first evaluation already showed the cached pose: nothing left to evaluate again.
            np.testing.assert_allclose(
                first.tips[frame], final, atol=1e-6, err_msg=f"frame {frame}"
            )
    finally:
        bpy.app.handlers.frame_change_post.remove(first)


def test_a_still_render_of_a_cached_frame_evaluates_it_once_with_the_played_pose(empty_scene):
    scene = empty_scene
    obj = _falling(scene)
    played, tips = {}, {}
    for frame in range(1, 13):
        scene.frame_set(frame)
        played[frame] = rotations(obj, "Ahoge")
        tips[frame] = _tips(obj, bpy.context.evaluated_depsgraph_get())
    assert np.abs(tips[12] - tips[7]).max() > 0.01, "gravity should swing the chain"
    scene.frame_current = 7  # a render of an earlier, cached frame (the viewport shows frame 12)
    scene.render.engine = "BLENDER_WORKBENCH"
    scene.render.resolution_x = scene.render.resolution_y = 16
    rendered = {}

    def record(scene, depsgraph=None):  # the render's own depsgraph, after the add-on's handler
        rendered[scene.frame_current] = np.array(
            [
                tuple(obj.evaluated_get(depsgraph).pose.bones[pb.name].rotation_quaternion)
                for pb in chain_bones(obj, "Ahoge")
            ]
        )

    bpy.app.handlers.frame_change_post.append(record)
    try:
        bpy.ops.render.render()
    finally:
        bpy.app.handlers.frame_change_post.remove(record)
    assert list(rendered) == [7]
    np.testing.assert_allclose(rendered[7], played[7], atol=1e-6)
    # The render wrote frame 7 into the viewport's copy too: the viewport must still show it right.
    scene.frame_set(7)
    final = _tips(obj, bpy.context.evaluated_depsgraph_get())
    np.testing.assert_allclose(final, tips[7], atol=1e-6)


def test_scrubbing_back_where_nothing_animates_shows_the_played_frames(empty_scene):
    # The rotations written before the evaluation reach Blender's copy, but nothing makes Blender
    # evaluate that pose again: the add-on must notice and have it evaluated.
    scene = empty_scene
    obj = _falling(scene)
    played = {}
    for frame in range(1, 25):
        scene.frame_set(frame)
        played[frame] = _tips(obj, bpy.context.evaluated_depsgraph_get())
    assert np.abs(played[12] - played[1]).max() > 0.01, "gravity should swing the chain"
    for frame in (10, 11, 15, 5, 20):
        scene.frame_set(frame)
        final = _tips(obj, bpy.context.evaluated_depsgraph_get())
        np.testing.assert_allclose(final, played[frame], atol=1e-6, err_msg=f"frame {frame}")
