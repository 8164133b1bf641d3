"""The next hair frame solved ahead while Blender evaluates this one (issue 13 item 2,
docs/algorithms.md §3.7).

A predicted frame's pre-frame handler starts the next frame's solve on native threads; the next
frame takes that result only when it is exactly what it would solve itself. Whatever the user
does between frames — edit the head's keys, change the scene's gravity or frame rate, jump,
scrub back, change a rod's settings, add a driver — every frame must show, through Blender's
evaluation, bit for bit the pose the plain path (every frame solved in its own handler) shows."""

import bpy
import numpy as np
import pytest
from hair_rig import add_camera, chain_bones, key_head, make_rig, select_only

CHAINS = (
    ("Ahoge", (0.0, 0.0, 1.8), (0.0, 0.0, 1.0), 5),
    ("Tail", (0.0, 0.1, 1.6), (0.0, 1.0, -0.3), 6),
)
HEAD_KEYS = (
    (1, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
    (6, (0.3, 0.0, 0.1), (0.3, 0.0, 0.2)),
    (12, (-0.3, 0.2, 0.0), (-0.2, 0.4, 0.0)),
    (20, (0.0, -0.1, 0.05), (0.0, 0.0, -0.3)),
)


def _rig(scene, head_by="action"):
    """Root -> Head with two rods (one with a view key) on the head, a camera flying round on
    its own keys. The head moves by its own keys, or copies a keyed control bone through a
    constraint (a rig whose inputs cannot be predicted)."""
    obj = make_rig(scene, CHAINS)
    select_only(obj, {"Ahoge.00", "Tail.00"})
    assert bpy.ops.kodawari.rod_add() == {"FINISHED"}
    camera = add_camera(scene, "Front", (0, -4, 1.7))
    select_only(obj, {"Ahoge.00"})
    for pb in chain_bones(obj, "Ahoge"):
        pb.rotation_quaternion = (0.966, 0.259, 0.0, 0.0)  # 30 degrees: the view key's shape
    obj.kodawari_hair.active_rod = 0
    assert bpy.ops.kodawari.rod_key_view(source="CAMERA", influence=1.0) == {"FINISHED"}
    for pb in chain_bones(obj, "Ahoge"):
        pb.rotation_quaternion = (1.0, 0.0, 0.0, 0.0)
    for frame, location in ((1, (0, -4, 1.7)), (15, (4, 0, 1.7)), (30, (0, 4, 1.7))):
        camera.location = location
        camera.keyframe_insert("location", frame=frame)
    driver = key_head(obj, HEAD_KEYS, by=head_by)
    scene.frame_start, scene.frame_end = 1, 60
    bpy.ops.object.mode_set(mode="OBJECT")
    return obj, driver


def _seen(obj):
    """The rod bones as Blender's evaluation shows them: rotations and joint positions."""
    evaluated = obj.evaluated_get(bpy.context.evaluated_depsgraph_get())
    names = [pb.name for name, *_ in CHAINS for pb in chain_bones(obj, name)]
    bones = [evaluated.pose.bones[n] for n in names]
    return np.array(
        [tuple(pb.rotation_quaternion) + tuple(pb.head) + tuple(pb.tail) for pb in bones]
    )


def _edit_head_key(obj, driver):
    driver.location = (0.1, -0.3, 0.2)
    driver.keyframe_insert("location", frame=10)  # frame 9 lies between new keys now


def _add_head_driver(obj, driver):
    fcurve = obj.driver_add(f'pose.bones["{driver.name}"].location', 2)
    fcurve.driver.type = "SCRIPTED"
    fcurve.driver.expression = "0.3"
    for modifier in list(fcurve.modifiers):
        fcurve.modifiers.remove(modifier)


# What a user does between frames: (frame set next, change made just before it, what it is).
SESSION = (
    [(f, None, "play") for f in range(1, 9)]
    + [(9, _edit_head_key, "the head's keys edited")]
    + [(f, None, "play") for f in range(10, 13)]
    + [(13, lambda obj, d: setattr(bpy.context.scene, "gravity", (0, 0, -4.0)), "gravity")]
    + [(f, None, "play") for f in range(14, 16)]
    + [(22, None, "a jump forward (16..21 replayed)")]
    + [(18, None, "scrub back"), (17, None, "scrub back")]
    + [(23, None, "on from the cache's end after a scrub"), (24, None, "play")]
    + [(25, lambda obj, d: setattr(bpy.context.scene.render, "fps", 30), "frame rate")]
    + [(f, None, "play") for f in range(26, 29)]
    + [(29, lambda obj, d: setattr(obj.kodawari_hair.rods[1], "stiffness", 0.7), "stiffness")]
    + [(f, None, "play") for f in range(30, 33)]
    + [(33, _add_head_driver, "a driver added to the head")]
    + [(f, None, "play") for f in range(34, 37)]
)


def _play_session(head_by, ahead, max_caller_share=1.0, evaluated_view=True, views_used=None):
    """Plays SESSION on a fresh rig, solving ahead or not; returns what every frame showed and,
    per frame set, the frames that took the result solved ahead (a jump or a rebuilt runtime
    replays several). Without evaluated_view the evaluated copy is written and read through RNA;
    views_used gets how often its memory was (runtime._evaluated_view)."""
    from kodawari.hair import runtime

    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    scene = bpy.context.scene
    obj, driver = _rig(scene, head_by)
    taken = []
    take = runtime.ArmatureRuntime._take_ahead
    start = runtime.ArmatureRuntime._start_ahead

    def spy(self, frame, *args):
        used = take(self, frame, *args)
        if used:
            taken.append(frame)
        return used

    runtime.ArmatureRuntime._take_ahead = spy
    views = runtime.ArmatureRuntime._evaluated_view
    used = []

    def spy_view(self, *args):
        view = views(self, *args) if evaluated_view else None
        used.append(view is not None)
        return view

    runtime.ArmatureRuntime._evaluated_view = spy_view
    min_bones, max_share = runtime.AHEAD_MIN_ROD_BONES, runtime.AHEAD_MAX_CALLER_SHARE
    runtime.AHEAD_MIN_ROD_BONES = 0  # this small rig solved ahead as a large one is
    # Never paused for a busy machine (a timing rule), unless the test asks for it.
    runtime.AHEAD_MAX_CALLER_SHARE = max_caller_share
    if not ahead:  # the plain path: every frame solved in its own handler
        runtime.ArmatureRuntime._start_ahead = lambda *args: None
    seen, taken_per_set = [], {}
    try:
        for frame, change, what in SESSION:
            if change is not None:
                change(obj, driver)
            taken.clear()
            scene.frame_set(frame)
            seen.append((frame, what, _seen(obj)))
            taken_per_set[frame] = list(taken)
    finally:
        runtime.ArmatureRuntime._take_ahead = take
        runtime.ArmatureRuntime._start_ahead = start
        runtime.ArmatureRuntime._evaluated_view = views
        runtime.AHEAD_MIN_ROD_BONES, runtime.AHEAD_MAX_CALLER_SHARE = min_bones, max_share
    if views_used is not None:
        views_used.append(sum(used))
    return seen, taken_per_set


def _assert_same(seen, reference):
    for (frame, what, pose), (_, _, expected) in zip(seen, reference):
        np.testing.assert_array_equal(pose, expected, err_msg=f"frame {frame} ({what})")


@pytest.mark.parametrize("head_by", ["action", "constraint"])
def test_frames_solved_ahead_show_exactly_the_plain_paths_poses_whatever_happens_between_them(
    empty_scene, head_by
):
    plain, never = _play_session(head_by, ahead=False)
    assert not any(never.values())
    seen, taken = _play_session(head_by, ahead=True)
    _assert_same(seen, plain)
    moved = np.abs(plain[14][2][:, :4] - plain[0][2][:, :4]).max()
    assert moved > 0.05, "the head should swing the hair"
    if head_by == "constraint":
        assert not any(taken.values()), "a rig whose inputs cannot be predicted is never ahead"
        return
    # Consecutive frames of plain playback take the frame solved ahead (the jump's replayed
    # frames too); a frame after a change that alters its solve never does. The first frame
    # after the start frame too: it is started once the start frame's pass is over.
    assert all(taken[f] == [f] for f in (2, 3, 4, 5, 6, 7, 8, 10, 14, 15, 24, 26, 30)), taken
    assert taken[22] == list(range(16, 23)), taken[22]
    refused = {9: "keys edited", 13: "gravity", 23: "after a scrub", 25: "frame rate"}
    for frame, why in refused.items():
        assert taken[frame] == [], f"frame {frame} ({why}) took a stale result"
    # Frame 33 is predicted as before (the driver is news to the prediction), solved ahead or
    # not the same, and refuted after Blender's evaluation: solved again from Blender's inputs.
    assert not any(taken[f] for f in (34, 35, 36)), "a refuted prediction stops solving ahead"


def test_frames_solved_in_place_while_the_step_ahead_pauses_show_the_same_poses(empty_scene):
    """A machine with no core to spare pauses the step ahead (runtime.AHEAD_MAX_CALLER_SHARE):
    here after every frame that took one, so the session mixes both paths."""
    plain, _ = _play_session("action", ahead=False)
    seen, taken = _play_session("action", ahead=True, max_caller_share=-1.0)
    _assert_same(seen, plain)
    assert taken[3] == [3], "the first frame after the start takes the one solved ahead"
    assert not any(taken[f] for f in range(4, 9)), "then 24 frames are solved in place"


def test_rotations_written_in_the_evaluated_copys_memory_show_the_rna_paths_poses(empty_scene):
    """The rod bones' rotations are written into (and checked in) the viewport's evaluated copy
    in its own memory, not through a foreach_set / foreach_get over every bone (runtime.
    _evaluated_view): every frame of the session, whatever happens between frames (a rebuilt
    runtime, a tag that has Blender copy the armature afresh), shows bit for bit what RNA shows."""
    used = []
    through_rna, _ = _play_session("action", ahead=True, evaluated_view=False, views_used=used)
    seen, _ = _play_session("action", ahead=True, views_used=used)
    _assert_same(seen, through_rna)
    assert used[0] == 0 and used[1] > len(SESSION), f"the copy's memory used {used[1]} times"


def test_a_rig_whose_few_input_bones_are_read_one_by_one_shows_the_same_poses(empty_scene):
    """Large rigs read their few input and other bones one by one (runtime.SPARSE_READ_RATIO:
    16,000 rod bones under a head), and then keep the predicted rotations through the check
    after the pass without restoring them: the session, solved ahead or not, shows bit for bit
    the poses of this small rig read in bulk."""
    from kodawari.hair import runtime

    plain, _ = _play_session("action", ahead=False)
    ratio = runtime.SPARSE_READ_RATIO
    runtime.SPARSE_READ_RATIO = 1  # every bone but the rods' is "few"
    try:
        for ahead in (False, True):
            seen, _ = _play_session("action", ahead=ahead)
            _assert_same(seen, plain)
    finally:
        runtime.SPARSE_READ_RATIO = ratio
