"""The FFD as a user sees it: rest round trip, rigid motions, smooth frames,
stable lengths and deterministic output (issue 2, "Must show")."""

import kodawari_native as kn
import numpy as np
import pytest


def helix(n=24, radius=1.0, pitch=0.15, turns=2.5):
    a = 2 * np.pi * turns * np.arange(n) / (n - 1)
    return np.column_stack([radius * np.cos(a), radius * np.sin(a), pitch * a])


def s_curve(n=16):
    x = np.linspace(0.0, 6.0, n)
    return np.column_stack([x, 0.8 * np.sin(x * np.pi / 2), 0.05 * x])


def fish_axis(n=6, length=4.0):
    return np.column_stack([np.linspace(0.0, length, n), np.zeros(n), np.zeros(n)])


def fish_mesh(count=20000, seed=5):
    """A spindle around the x axis, with snout and tail points past the axis ends."""
    rng = np.random.default_rng(seed)
    x = rng.uniform(-0.3, 4.3, count)
    radius = 0.5 * np.sqrt(np.clip(1 - ((x - 2.0) / 2.4) ** 2, 0, 1)) * rng.random(count)
    angle = rng.uniform(0, 2 * np.pi, count)
    return np.column_stack([x, radius * np.cos(angle), 0.6 * radius * np.sin(angle)]).astype(
        np.float32
    )


def rotation(axis, angle):
    axis = np.asarray(axis, float) / np.linalg.norm(axis)
    k = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + np.sin(angle) * k + (1 - np.cos(angle)) * k @ k


@pytest.mark.parametrize("axis_name", ["straight", "helix", "s_curve"])
def test_deform_at_rest_reproduces_the_mesh(axis_name):
    axis = {"straight": fish_axis(), "helix": helix(), "s_curve": s_curve()}[axis_name]
    frames = kn.ffd_frames(axis, samples=4001)
    rng = np.random.default_rng(1)
    pick = rng.integers(0, 4001, 20000)
    angle = rng.uniform(0, 2 * np.pi, 20000)
    radius = 0.3 * rng.random(20000)
    mesh = (
        frames[pick, 0]
        + (radius * np.cos(angle))[:, None] * frames[pick, 2]
        + (radius * np.sin(angle))[:, None] * frames[pick, 3]
    ).astype(np.float32)
    twist = np.linspace(0.0, 0.8, len(axis))
    binding = kn.ffd_bind(axis, mesh, twist=twist)
    out = np.empty_like(mesh)
    binding.deform(axis, out, twist=twist)
    assert np.abs(out - mesh).max() < 1e-5 * kn.curve_length(axis)


def test_rigid_motion_of_the_control_points_moves_the_mesh_rigidly():
    axis, mesh = fish_axis(), fish_mesh()
    axis[2:, 1] += [0.2, 0.5, 0.3, -0.1]  # a bent rest axis, so the motion is not trivially along x
    up = np.array([0.0, 0.0, 1.0])
    binding = kn.ffd_bind(axis, mesh, up=up)
    r = rotation([0.4, -1.0, 0.7], 2.3)
    shift = np.array([5.0, -2.0, 1.5])
    out = np.empty_like(mesh)
    binding.deform(axis @ r.T + shift, out, up=r @ up)
    expected = mesh.astype(np.float64) @ r.T + shift
    assert np.abs(out - expected).max() < 1e-5 * kn.curve_length(axis)


def test_snout_and_tail_tip_follow_the_end_frames():
    axis, mesh = fish_axis(), fish_mesh()
    binding = kn.ffd_bind(axis, mesh)
    past_tail = mesh[:, 0] > 4.0
    assert (
        past_tail.any()
        and np.all(binding.w[past_tail] > 0)
        and np.all(binding.w[mesh[:, 0] < 0] < 0)
    )
    bent = axis.copy()
    bent[5] = bent[4] + [0.0, 0.8, 0.0]  # tail leg turned 90 degrees
    out = np.empty_like(mesh)
    binding.deform(bent, out)
    # The tail tip moved with the end frame: it sits past the new end along +y, not left behind along +x.
    tip = out[past_tail]
    assert np.all(tip[:, 1] > bent[5, 1] - 1e-4)
    np.testing.assert_allclose(tip[:, 1] - bent[5, 1], binding.w[past_tail], atol=1e-5)


def frame_turns(frames):
    """Per step: rotation angle of the whole frame, and the turn of the tangent."""
    basis = frames[:, 1:, :]
    relative = np.einsum("ikj,ikl->ijl", basis[1:], basis[:-1])  # B_{i+1}^T B_i
    cos_frame = np.clip((np.trace(relative, axis1=1, axis2=2) - 1) / 2, -1, 1)
    cos_tangent = np.clip(np.einsum("ij,ij->i", basis[1:, 0], basis[:-1, 0]), -1, 1)
    return np.arccos(cos_frame), np.arccos(cos_tangent)


@pytest.mark.parametrize("axis", [helix(), s_curve()], ids=["helix", "s_curve"])
def test_successive_frames_never_turn_more_than_the_curve(axis):
    frame_angle, tangent_angle = frame_turns(kn.ffd_frames(axis, samples=400))
    assert np.all(frame_angle <= tangent_angle * 1.001 + 1e-7), np.max(frame_angle - tangent_angle)


def test_bent_axis_keeps_arc_length_after_the_length_pass():
    rest = fish_axis(8, 1.0)
    rest_lengths = np.linalg.norm(np.diff(rest, axis=0), axis=1)
    rest_arc = kn.curve_length(rest)
    s = np.linspace(0, 1, 8)
    for phase in np.linspace(0, 2 * np.pi, 8, endpoint=False):
        bent = rest.copy()
        bent[:, 1] += 0.08 * s * s * np.sin(2 * np.pi * s - phase)
        assert abs(kn.curve_length(bent) / rest_arc - 1) > 0.005  # the raw bend stretches the body
        kept = kn.preserve_lengths_from_head(bent, rest_lengths)
        assert abs(kn.curve_length(kept) / rest_arc - 1) < 0.005
        # with the arc-length target the match is exact even for a wild swing
        wild = rest.copy()
        wild[:, 1] += 0.25 * s * s * np.sin(2 * np.pi * s - phase)
        exact = kn.preserve_lengths_from_head(wild, rest_lengths, arc_length=rest_arc)
        assert kn.curve_length(exact) == pytest.approx(rest_arc, rel=1e-8)


def test_results_are_identical_across_runs_and_thread_counts():
    axis, mesh = fish_axis(), fish_mesh(150001)
    twist = np.array([0.0, 0.1, -0.2, 0.3, 0.0, 0.5])
    bent = axis.copy()
    bent[:, 1] = 0.4 * np.sin(np.linspace(0, 3, 6))
    first = kn.ffd_bind(axis, mesh, twist=twist)
    second = kn.ffd_bind(axis, mesh, twist=twist)
    for name in "tuvw":
        np.testing.assert_array_equal(getattr(first, name), getattr(second, name))
    reference = np.empty_like(mesh)
    first.deform(bent, reference, twist=twist, threads=1)
    for threads in (0, 1, 2, 3, 7):
        out = np.empty_like(mesh)
        second.deform(bent, out, twist=twist, threads=threads)
        assert out.tobytes() == reference.tobytes(), threads
