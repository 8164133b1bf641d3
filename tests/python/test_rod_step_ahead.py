"""RodStepAhead: a rod system's next frame stepped on a worker thread (docs/algorithms.md §3.7).

What the add-on relies on: a step taken ahead and adopted gives, bit for bit, the rotations and
the state the system's own step gives; the system can be read, cached and stepped while the
step runs; and a result is never adopted onto a state other than the one it started from."""

import kodawari_native as kn
import numpy as np
import pytest
from rod_chain import axis_angle_quat, quat_to_matrix

RODS, BONES = 24, 8
BONE_COUNT = 2 + RODS * BONES  # bone 0 the head, bone 1 a collider, then the chains
GRAVITY = np.array([0.0, 0.0, -9.81])
CAMERA = np.array([0.3, -4.0, 1.7])


def _system():
    system = kn.RodSystem(BONE_COUNT, 0)
    offsets = np.array([(0.0, 0.1, 0.0)] + [(0.0, 0.03, 0.0)] * BONES)
    rest = np.tile([1.0, 0.0, 0.0, 0.0], (BONES, 1))
    curl = np.tile(axis_angle_quat((1, 0, 0), 0.3), (BONES, 1))
    for r in range(RODS):
        system.add_rod(
            0,
            0,
            np.arange(2 + r * BONES, 2 + (r + 1) * BONES, dtype=np.int32),
            offsets,
            rest,
            wind=np.array([0.5, 0.0, 0.0]),  # gusts: the time input matters
            key_conditions=np.zeros(1, np.int32),  # a view key: the camera matters
            key_directions=np.array([[0.0, 0.0, 1.0]]),
            key_rotations=np.array([[1.0, 0.0, 0.0, 0.0]]),
            key_speeds=np.zeros(1),
            key_influences=np.array([2.0]),
            key_shapes=curl,
        )
    system.set_colliders(
        np.array([1], np.int32),
        np.zeros(1, np.int32),
        np.zeros((1, 3)),
        np.array([0.05]),
        np.zeros(1),
    )
    return system


def _matrices(frame):
    """The head swings and turns; a collider sphere sweeps through the chains."""
    m = np.tile(np.eye(4), (BONE_COUNT, 1, 1))
    m[0, :3, :3] = quat_to_matrix(axis_angle_quat((0, 0, 1), 0.6 * np.sin(frame / 4)))
    m[0, :3, 3] = (0.2 * np.sin(frame / 5), 0.0, 0.1 * np.cos(frame / 3))
    m[1, :3, 3] = (0.3 * np.cos(frame / 6), 0.15, 0.0)
    return np.ascontiguousarray(m.transpose(0, 2, 1).reshape(BONE_COUNT, 16), np.float32)


def _inputs(frame):
    return dict(
        bone_matrices=_matrices(frame),
        armature_matrix=np.eye(4),
        camera=CAMERA,
        gravity=GRAVITY,
        time=frame / 24,
        frame_dt=1 / 24,
    )


def _started(frames=1):
    system = _system()
    out = np.zeros((BONE_COUNT, 4), np.float32)
    system.reset(_matrices(1), np.eye(4), CAMERA, GRAVITY, 1 / 24, out)
    for frame in range(2, 2 + frames):
        system.step(rotations_out=out, **_inputs(frame))
    return system, out


def test_frames_stepped_ahead_and_adopted_are_bit_for_bit_the_systems_own_steps():
    played, out = _started()
    ahead_system, ahead_out = _started()
    ahead = kn.RodStepAhead()
    for frame in range(3, 40):
        ahead.start(ahead_system, **_inputs(frame))
        played.step(rotations_out=out, **_inputs(frame))
        assert ahead.finish(ahead_out)
        assert ahead.adopt(ahead_system)
        np.testing.assert_array_equal(ahead_out, out, err_msg=f"frame {frame}")
        np.testing.assert_array_equal(ahead_system.save_state(), played.save_state())
        np.testing.assert_array_equal(ahead_system.weights(3), played.weights(3))
    assert np.abs(out[2:] - out[2:].mean(axis=0)).max() > 1e-3, "the chains should move"


def test_the_system_is_read_cached_and_stepped_while_a_step_runs_and_a_moved_state_is_refused():
    system, out = _started()
    before = system.save_state()
    ahead = kn.RodStepAhead(threads=1)
    ahead.start(system, **_inputs(3))
    assert ahead.started
    # The system itself is untouched: still the state before the step, usable at once.
    np.testing.assert_array_equal(system.save_state(), before)
    system.store_frame(2, out)
    system.joint_positions(0)
    assert ahead.finish(np.zeros((BONE_COUNT, 4), np.float32))
    system.step(rotations_out=out, **_inputs(3))  # the state moves on: the step ahead is stale
    moved = system.save_state()
    assert not ahead.adopt(system)
    np.testing.assert_array_equal(system.save_state(), moved)
    # Back to the cached frame 2 (the same values, but a new state): still refused.
    ahead.start(system, **_inputs(4))
    system.recall_frame(2)
    assert ahead.finish(np.zeros((BONE_COUNT, 4), np.float32))
    assert not ahead.adopt(system)


def test_a_step_is_adopted_only_by_the_system_it_started_from_and_only_once():
    system, _ = _started()
    twin, _ = _started()
    ahead = kn.RodStepAhead()
    assert not ahead.finish(np.zeros((BONE_COUNT, 4), np.float32)), "nothing started"
    assert not ahead.adopt(system)
    ahead.start(system, **_inputs(3))
    assert ahead.finish(np.zeros((BONE_COUNT, 4), np.float32))
    assert not ahead.adopt(twin), "the same values, but another system"
    assert ahead.adopt(system)
    assert not ahead.adopt(system), "a result is adopted once"
    with pytest.raises(ValueError, match="rotations_out"):
        ahead.start(system, **_inputs(4))
        ahead.finish(np.zeros((BONE_COUNT + 1, 4), np.float32))


def test_a_step_ahead_refuses_bad_inputs_before_it_starts():
    system, _ = _started()
    ahead = kn.RodStepAhead()
    bad = _inputs(3)
    bad["armature_matrix"] = np.zeros((4, 4))
    with pytest.raises(ValueError, match="armature_matrix"):
        ahead.start(system, **bad)
    assert not ahead.started


def test_the_snapshot_made_on_the_thread_caches_the_frame_bit_for_bit_as_store_frame_does():
    played, out = _started(frames=3)
    ahead_system, ahead_out = _started(frames=3)
    ahead = kn.RodStepAhead()
    ahead.start(ahead_system, rotations=ahead_out, **_inputs(5))
    played.store_frame(4, out)
    assert ahead.store(ahead_system, 4)
    assert not ahead.store(ahead_system, 4), "one snapshot per start"
    np.testing.assert_array_equal(ahead_system.cached_state(4), played.cached_state(4))
    np.testing.assert_array_equal(ahead_system.cached_rotations(4), played.cached_rotations(4))
    # Stepping on from the cached frame gives what the played system gives.
    assert ahead.finish(ahead_out) and ahead.adopt(ahead_system)
    played.step(rotations_out=out, **_inputs(5))
    ahead_system.recall_frame(4)
    ahead_system.step(rotations_out=ahead_out, **_inputs(5))
    np.testing.assert_array_equal(ahead_out, out)


def test_a_snapshot_of_a_state_the_system_no_longer_holds_is_not_cached():
    system, out = _started()
    ahead = kn.RodStepAhead()
    ahead.start(system, rotations=out, **_inputs(3))
    system.step(rotations_out=out, **_inputs(3))  # the system moved on
    assert not ahead.store(system, 2)
    assert system.cached_frames() == []
    ahead.start(system, **_inputs(4))  # no rotations: no snapshot
    assert not ahead.store(system, 3)


def test_a_step_started_again_drops_the_earlier_one_and_gives_the_new_inputs_step():
    played, out = _started()
    ahead_system, ahead_out = _started()
    ahead = kn.RodStepAhead()
    ahead.start(ahead_system, **_inputs(7))  # dropped: its frame took another path
    ahead.start(ahead_system, **_inputs(3))
    assert ahead.finish(ahead_out) and ahead.adopt(ahead_system)
    played.step(rotations_out=out, **_inputs(3))
    np.testing.assert_array_equal(ahead_out, out)
    np.testing.assert_array_equal(ahead_system.save_state(), played.save_state())


def test_a_state_changed_while_the_thread_copies_it_waits_and_each_side_steps_the_right_state():
    """The twin's copy of the state is made on the thread, off the caller's frame: a change of
    the system made right after start() (a frame solved in place, a recalled frame) waits for that
    copy, so the step ahead and the system's own step each start from the state they should."""
    played, out = _started()
    system, system_out = _started()
    ahead = kn.RodStepAhead()
    ahead.start(
        system, **_inputs(3)
    )  # the first start makes the twin; later ones copy on the thread
    assert ahead.finish(system_out) and ahead.adopt(system)
    played.step(rotations_out=out, **_inputs(3))
    for frame in range(4, 12):
        reference = played.save_state()
        ahead.start(system, **_inputs(frame))
        system.step(rotations_out=system_out, **_inputs(frame + 7))  # at once: the copy in flight
        ahead_out = np.zeros((BONE_COUNT, 4), np.float32)
        assert ahead.finish(ahead_out)
        assert not ahead.adopt(system), "the state moved on after the start"
        played.step(rotations_out=out, **_inputs(frame))
        np.testing.assert_array_equal(ahead_out[2:], out[2:], err_msg=f"frame {frame} ahead")
        jumped, jumped_out = _started()  # frame + 7's step from the same state, elsewhere
        jumped.load_state(reference)
        jumped.step(rotations_out=jumped_out, **_inputs(frame + 7))
        np.testing.assert_array_equal(system_out[2:], jumped_out[2:], err_msg=f"frame {frame}")
        np.testing.assert_array_equal(system.save_state(), jumped.save_state())
        system.load_state(played.save_state())  # back in step with the played system
    ahead.start(system, **_inputs(12))
    del system  # a system dropped while the thread copies it waits for the copy (no crash)
    assert ahead.finish(np.zeros((BONE_COUNT, 4), np.float32))
