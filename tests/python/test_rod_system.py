"""The rod solver (kodawari_native.RodSystem) against the behaviour issue 4 asks for."""

import kodawari_native as kn
import numpy as np
import pytest
from rod_chain import Chain, axis_angle_quat, quat_to_matrix

NO_GRAVITY = (0.0, 0.0, 0.0)
IDENTITY = [1.0, 0.0, 0.0, 0.0]


def angle_deg(q1, q2):
    d = abs(float(np.dot(q1 / np.linalg.norm(q1), q2 / np.linalg.norm(q2))))
    return np.degrees(2 * np.arccos(min(1.0, d)))


def curl(axis, degrees, bones=6):
    return [axis_angle_quat(axis, np.radians(degrees)).tolist()] * bones


def joint_angles(out, shape):
    return [
        angle_deg(out[k + 1].astype(float), np.asarray(shape[k], float)) for k in range(len(shape))
    ]


def test_without_keys_and_gravity_the_chain_settles_back_to_rest_after_the_head_moves():
    chain = Chain(stiffness=0.5)
    chain.reset(gravity=NO_GRAVITY)
    for frame in range(24):
        t = frame / 24
        chain.head_position = np.array([0.4 * np.sin(6 * t), 0.1 * t, 0.0])
        chain.head_rotation = quat_to_matrix(axis_angle_quat((0, 0, 1), 0.8 * np.sin(5 * t)))
        chain.step(gravity=NO_GRAVITY)
    moved = max(joint_angles(chain.out, [IDENTITY] * 6))
    assert moved > 5, "the head's motion should swing the chain"
    for _ in range(240):
        chain.step(gravity=NO_GRAVITY)
    assert max(joint_angles(chain.out, [IDENTITY] * 6)) < 0.5
    np.testing.assert_allclose(chain.positions(), chain.rest_positions([IDENTITY] * 6), atol=2e-3)


def test_a_far_move_over_a_vanishing_frame_step_keeps_the_state_finite():
    # The head's speed is its move over the frame's step: 3e8 over 1e-300 s overflowed to
    # inf and was kept in the saved state (found by the fuzz tier). Finite inputs must give
    # a finite state, and the chain must go on stepping normally from it.
    chain = Chain()
    chain.reset()
    chain.head_position = np.array([3e8, 0.0, 0.0])
    chain.step(dt=1e-300)
    assert np.isfinite(chain.system.save_state()).all()
    chain.head_position = np.array([3e8, 0.1, 0.0])
    chain.step()
    assert np.isfinite(chain.system.save_state()).all() and np.isfinite(chain.positions()).all()


def test_camera_on_a_keyed_direction_with_large_influence_settles_on_that_key_within_2_degrees():
    shape = curl((0, 0, 1), 15)
    chain = Chain(keys=[dict(condition=0, direction=(1, 0, 0), influence=64.0, shape=shape)])
    chain.reset(camera=(0, 0, 5), gravity=NO_GRAVITY)
    for _ in range(120):
        chain.step(camera=(5, 0, 0), gravity=NO_GRAVITY)
    assert chain.system.weights(0)[1] == pytest.approx(1.0)
    assert max(joint_angles(chain.out, shape)) < 2.0
    np.testing.assert_allclose(chain.positions(), chain.rest_positions(shape), atol=5e-3)


def test_between_two_keys_the_chain_takes_their_blend():
    a = curl((0, 0, 1), 20)
    b = curl((1, 0, 0), 20)
    keys = [
        dict(condition=0, direction=(1, 0, 0), influence=1.0, shape=a),
        dict(condition=0, direction=(-1, 0, 0), influence=1.0, shape=b),
    ]
    chain = Chain(keys=keys)
    chain.reset(camera=(0, 0, 5), gravity=NO_GRAVITY)
    for _ in range(120):
        chain.step(camera=(0, 0, 5), gravity=NO_GRAVITY)
    w = chain.system.weights(0)
    np.testing.assert_allclose(
        w, kn.view_weights(np.array([[1.0, 0, 0], [-1.0, 0, 0]]), np.ones(2), np.array([0, 0, 1.0]))
    )
    np.testing.assert_allclose(w, [0.0, 0.5, 0.5])
    blend = (np.array(a[0]) + np.array(b[0])) / 2
    blend /= np.linalg.norm(blend)
    angles = joint_angles(chain.out, [blend] * 6)
    assert max(angles) < 2.0
    assert min(joint_angles(chain.out, a)) > 5 and min(joint_angles(chain.out, b)) > 5


def test_bone_lengths_stay_within_a_tenth_of_a_percent_every_frame():
    sphere = (
        np.array([0], np.int32),
        np.array([0], np.int32),
        np.zeros((1, 3)),
        np.array([0.15]),
        np.zeros(1),
    )
    chain = Chain(
        bones=12, length=0.05, stiffness=0.3, colliders=sphere, wind=np.array([3.0, 0, 0])
    )
    chain.reset()
    worst = 0.0
    for frame in range(96):
        t = frame / 24
        chain.head_position = np.array(
            [0.5 * np.sin(9 * t), 0.3 * np.cos(7 * t), 0.2 * np.sin(13 * t)]
        )
        chain.head_rotation = quat_to_matrix(axis_angle_quat((1, 1, 0), 2.0 * np.sin(8 * t)))
        chain.step()
        lengths = np.linalg.norm(np.diff(chain.positions(), axis=0), axis=1)
        worst = max(worst, np.abs(lengths / 0.05 - 1).max())
    assert worst < 1e-3


def test_colliders_keep_every_joint_outside_the_head_sphere():
    radius = 0.15
    sphere = (
        np.array([0], np.int32),
        np.array([0], np.int32),
        np.zeros((1, 3)),
        np.array([radius]),
        np.zeros(1),
    )
    chain = Chain(bones=10, length=0.06, stiffness=0.2, radius=0.01, colliders=sphere)
    chain.reset()
    closest = np.inf
    for frame in range(120):
        t = frame / 24
        chain.head_rotation = quat_to_matrix(axis_angle_quat((0, 0, 1), 1.5 * np.sin(3 * t)))
        chain.step(gravity=(0.0, -9.81, 0.0))  # pulls the chain onto the head
        distance = np.linalg.norm(chain.positions() - chain.head_position, axis=1)
        closest = min(closest, distance.min())
    assert closest >= radius
    # Without the collider the same motion drives joints into the sphere: the test has teeth.
    free = Chain(bones=10, length=0.06, stiffness=0.2, radius=0.01)
    free.reset()
    inside = False
    for frame in range(120):
        t = frame / 24
        free.head_rotation = quat_to_matrix(axis_angle_quat((0, 0, 1), 1.5 * np.sin(3 * t)))
        free.step(gravity=(0.0, -9.81, 0.0))
        inside |= bool((np.linalg.norm(free.positions(), axis=1) < radius).any())
    assert inside


def _cut_run(momentum_control):
    keys = [
        dict(condition=0, direction=(1, 0, 0), influence=8.0, shape=curl((0, 0, 1), 30)),
        dict(condition=0, direction=(-1, 0, 0), influence=8.0, shape=curl((0, 0, 1), -30)),
    ]
    chain = Chain(keys=keys, momentum_control=momentum_control)
    chain.reset(camera=(5, 0, 0), gravity=NO_GRAVITY)
    for _ in range(60):
        chain.step(camera=(5, 0, 0), gravity=NO_GRAVITY)
    before = np.abs(chain.system.joint_velocities(0)).max()
    chain.step(camera=(-5, 0, 0), gravity=NO_GRAVITY)  # the camera cut
    after = np.linalg.norm(chain.system.joint_velocities(0), axis=1).max()
    peak = after
    for _ in range(24):
        chain.step(camera=(-5, 0, 0), gravity=NO_GRAVITY)
        peak = max(peak, np.linalg.norm(chain.system.joint_velocities(0), axis=1).max())
    return before, after, peak, chain


def test_a_camera_cut_adds_no_momentum():
    before, after, peak, chain = _cut_run(True)
    assert before < 1e-3
    assert after < 1e-2 and peak < 1e-2  # m/s: nothing is flung
    assert (
        max(joint_angles(chain.out, curl((0, 0, 1), -30))) < 2.0
    )  # yet the new key's shape is taken
    _, after_free, peak_free, _ = _cut_run(False)
    assert peak_free > 0.3, "without momentum control the same cut flings the chain"


def test_pose_and_speed_keys_weigh_by_their_own_similarity():
    turned = axis_angle_quat((0, 0, 1), np.pi / 2)
    keys = [
        dict(condition=1, rotation=turned, influence=4.0, shape=curl((1, 0, 0), 20)),
        dict(condition=2, speed=2.0, influence=4.0, shape=curl((0, 0, 1), 20)),
    ]
    chain = Chain(keys=keys)
    chain.reset(gravity=NO_GRAVITY)
    chain.step(gravity=NO_GRAVITY)
    w = chain.system.weights(0)
    # Head unturned: pose similarity cos(90°) -> (0 + 1) / 2; at rest speed similarity exp(-1).
    np.testing.assert_allclose(w[1:], [0.5**4, np.exp(-1.0) ** 4], rtol=1e-9)
    chain.head_rotation = quat_to_matrix(turned)
    for _ in range(3):
        chain.head_position = chain.head_position + np.array([2.0 / 24, 0, 0])
        chain.step(gravity=NO_GRAVITY)
    assert chain.system.reference_speed(0) == pytest.approx(2.0, rel=1e-5)
    w = chain.system.weights(0)
    assert (
        w[1] == pytest.approx(0.5, rel=1e-5)
        and w[2] == pytest.approx(0.5, rel=1e-5)
        and w[0] < 1e-6
    )


def _run_many(threads, frames=30):
    system = kn.RodSystem(1 + 40 * 5, threads)
    for r in range(40):
        system.add_rod(
            0,
            0,
            np.arange(1 + 5 * r, 6 + 5 * r, dtype=np.int32),
            np.array([(0.01 * r, 0.2, 0)] + [(0, 0.1, 0)] * 5, float),
            np.tile([1.0, 0, 0, 0], (5, 1)),
            stiffness=0.4,
            wind=np.array([1.0, 0, 0.5]),
            key_conditions=np.zeros(1, np.int32),
            key_directions=np.array([[1.0, 0, 0]]),
            key_rotations=np.array([[1.0, 0, 0, 0]]),
            key_speeds=np.zeros(1),
            key_influences=np.array([2.4]),
            key_shapes=np.array(curl((0, 0, 1), 25, 5)),
        )
    out = np.zeros((system.bone_count, 4), np.float32)
    results = []
    matrices = np.tile(np.eye(4, dtype=np.float32).reshape(16), (system.bone_count, 1))
    system.reset(matrices, np.eye(4), np.array([3.0, 1, 0]), np.array([0, 0, -9.81]), 0.0, out)
    for frame in range(frames):
        matrices[0, 12] = 0.3 * np.sin(frame / 4)  # head x (column-major translation)
        system.step(
            matrices,
            np.eye(4),
            np.array([3.0 * np.cos(frame / 10), 3.0 * np.sin(frame / 10), 0]),
            np.array([0, 0, -9.81]),
            (frame + 1) / 24,
            1 / 24,
            out,
        )
        results.append(out.copy())
    return system, np.array(results)


def test_the_same_inputs_give_bit_identical_outputs_for_any_thread_count():
    _, one = _run_many(1)
    _, two = _run_many(2)
    _, again = _run_many(2)
    assert one.tobytes() == two.tobytes() == again.tobytes()


def test_saved_state_continues_exactly():
    system, _ = _run_many(2, frames=10)
    state = system.save_state()
    out = np.zeros((system.bone_count, 4), np.float32)
    matrices = np.tile(np.eye(4, dtype=np.float32).reshape(16), (system.bone_count, 1))
    runs = []
    for _ in range(2):
        system.load_state(state)
        frames = []
        for frame in range(10):
            matrices[0, 12] = 0.2 * frame
            system.step(
                matrices,
                np.eye(4),
                np.array([3.0, 0, 0]),
                np.array([0, 0, -9.81]),
                1 + frame / 24,
                1 / 24,
                out,
            )
            frames.append(out.copy())
        runs.append(np.array(frames))
    assert runs[0].tobytes() == runs[1].tobytes()
    # A fresh system with the same rods (as after reopening a file) continues the same way:
    # the state carries everything, the keyed rest shape included.
    fresh, _ = _run_many(1, frames=0)
    fresh.load_state(state)
    system.load_state(state)
    for r in range(fresh.rod_count):
        np.testing.assert_array_equal(fresh.rest_shape(r), system.rest_shape(r))
    fresh_out = np.zeros_like(out)
    for frame in range(10):
        matrices[0, 12] = 0.2 * frame
        camera = np.array(
            [3.0 * np.cos(frame), 3.0 * np.sin(frame), 0]
        )  # the view keys' weights change
        for s, o in ((system, out), (fresh, fresh_out)):
            s.step(matrices, np.eye(4), camera, np.array([0, 0, -9.81]), 1 + frame / 24, 1 / 24, o)
        assert fresh_out.tobytes() == out.tobytes()
    with pytest.raises(ValueError, match="state has"):
        system.load_state(state[:-1])


def test_the_native_frame_cache_recalls_a_frame_exactly_and_continues_from_it():
    chain = Chain(bones=5)
    chain.reset()
    chain.system.store_frame(1, chain.out)
    written = {}
    for frame in range(2, 12):
        chain.head_position = np.array([0.05 * frame, 0.0, 0.0])
        chain.step()
        chain.system.store_frame(frame, chain.out)
        written[frame] = (chain.out.copy(), chain.system.save_state(), chain.time)
    assert chain.system.cached_frames() == list(range(1, 12))
    assert chain.system.latest_cached_frame_before(7) == 6
    assert chain.system.latest_cached_frame_before(1) is None
    # Rotations come back rod by rod, root first (here the bones 1..5 in order).
    np.testing.assert_array_equal(chain.system.cached_rotations(4), written[4][0][1:])
    np.testing.assert_array_equal(chain.system.cached_state(4), written[4][1])
    # Recall frame 6, play on: frames 7.. repeat bit for bit.
    out = np.zeros_like(chain.out)
    assert chain.system.recall_frame(6, out)
    np.testing.assert_array_equal(out[1:], written[6][0][1:])
    chain.time = written[6][2]
    for frame in range(7, 12):
        chain.head_position = np.array([0.05 * frame, 0.0, 0.0])
        assert chain.step().tobytes() == written[frame][0].tobytes()
    assert not chain.system.recall_frame(40, out)
    chain.system.clear_cache()
    assert chain.system.cached_frames() == [] and chain.system.cached_state(4) is None
    with pytest.raises(ValueError, match="rotations"):
        chain.system.store_frame(2, np.zeros((2, 4), np.float32))


def test_the_substep_rate_does_not_depend_on_the_frame_rate():
    def run(fps):
        chain = Chain(substeps=4)
        chain.reset()
        for frame in range(fps):
            t = (frame + 1) / fps
            chain.head_position = np.array([0.3 * t, 0.0, 0.0])
            chain.step(dt=1 / fps)
        return chain.positions()

    # The substeps fall at the same simulated times at any frame rate. The energy budget
    # (docs/algorithms.md §3.3) also holds every frame end to its budget, so no frame shows an
    # energy gain at any frame rate; where those checks act, here while the strand falls and the
    # head drags it, 24 and 48 fps end 3.0 mm apart (0 before the budget; 24 and 30 fps were
    # 1.9 mm apart then, 3.5 mm now).
    np.testing.assert_allclose(run(24), run(48), atol=5e-3)


def _add(system, **overrides):
    args = dict(
        parent_bone=0,
        reference_bone=0,
        bones=np.array([1, 2], np.int32),
        offsets=np.array([(0, 0.2, 0), (0, 0.1, 0), (0, 0.1, 0)], float),
        rest_rotations=np.tile([1.0, 0, 0, 0], (2, 1)),
        wind=np.zeros(3),
        key_conditions=np.zeros(1, np.int32),
        key_directions=np.array([[1.0, 0, 0]]),
        key_rotations=np.array([[1.0, 0, 0, 0]]),
        key_speeds=np.zeros(1),
        key_influences=np.ones(1),
        key_shapes=np.tile([1.0, 0, 0, 0], (2, 1)),
    )
    args.update(overrides)
    return system.add_rod(**args)


@pytest.mark.parametrize(
    "overrides, message",
    [
        (
            dict(
                bones=np.zeros(0, np.int32),
                offsets=np.zeros((1, 3)),
                rest_rotations=np.zeros((0, 4)),
                key_shapes=np.zeros((0, 4)),
            ),
            "at least one joint",
        ),
        (dict(offsets=np.array([(0, 0.2, 0), (0, 0.0, 0), (0, 0.1, 0)], float)), "zero length"),
        (dict(key_shapes=np.array([[np.nan, 0, 0, 0], [1.0, 0, 0, 0]])), "NaN"),
        (dict(key_directions=np.zeros((1, 3))), "zero or NaN direction"),
        (dict(bones=np.array([1, 7], np.int32)), "outside the armature"),
        (dict(stiffness=0.0), "stiffness"),
        (dict(key_influences=np.array([-1.0])), "influences"),
        (dict(bones=np.array([1.0, 2.0])), "int32"),
    ],
)
def test_bad_rods_are_refused_with_a_clear_message_and_change_nothing(overrides, message):
    system = kn.RodSystem(3)
    with pytest.raises(ValueError, match=message):
        _add(system, **overrides)
    assert system.rod_count == 0
    assert _add(system) == 0
