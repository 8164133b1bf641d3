"""Every bad input to the FFD raises ValueError naming the argument, never a crash."""

import kodawari_native as kn
import numpy as np
import pytest

AXIS = np.column_stack([np.linspace(0.0, 4.0, 5), np.zeros(5), np.zeros(5)])
MESH = np.random.default_rng(0).random((50, 3)).astype(np.float32)


def with_value(array, index, value):
    bad = array.copy()
    bad[index] = value
    return bad


def coincident(array):
    bad = array.copy()
    bad[2] = bad[1]
    return bad


BAD_CONTROL_POINTS = {
    "wrong shape": AXIS[:, :2].copy(),
    "1-D": AXIS.reshape(-1).copy(),
    "wrong dtype": AXIS.astype(np.float32),
    "non-contiguous": np.asfortranarray(AXIS),
    "NaN": with_value(AXIS, (1, 1), np.nan),
    "inf": with_value(AXIS, (3, 0), np.inf),
    "fewer than 4": AXIS[:3].copy(),
    "coincident": coincident(AXIS),
    "not an array": AXIS.tolist(),
}

BAD_VERTICES = {
    "wrong shape": MESH[:, :2].copy(),
    "wrong dtype": MESH.astype(np.float64),
    "non-contiguous": MESH[::2],
    "NaN": with_value(MESH, (4, 2), np.nan),
    "inf": with_value(MESH, (0, 0), -np.inf),
    "empty": np.empty((0, 3), np.float32),
}


@pytest.mark.parametrize("case", list(BAD_CONTROL_POINTS))
def test_bad_control_points_everywhere(case):
    bad = BAD_CONTROL_POINTS[case]
    binding = kn.ffd_bind(AXIS, MESH)
    out = np.empty_like(MESH)
    calls = [
        lambda: kn.ffd_bind(bad, MESH),
        lambda: binding.deform(bad, out),
        lambda: kn.ffd_frames(bad),
        lambda: kn.curve_points(bad, np.array([0.5])),
        lambda: kn.curve_length(bad),
    ]
    for call in calls:
        with pytest.raises(ValueError, match="control_points"):
            call()


@pytest.mark.parametrize("case", list(BAD_VERTICES))
def test_bad_vertices(case):
    with pytest.raises(ValueError, match="vertices"):
        kn.ffd_bind(AXIS, BAD_VERTICES[case])


@pytest.mark.parametrize(
    "bad",
    [np.zeros(4), np.zeros(5, np.float32), np.array([0, 0, np.nan, 0, 0.0]), np.zeros((5, 1))],
    ids=["length", "dtype", "NaN", "shape"],
)
def test_bad_twist(bad):
    with pytest.raises(ValueError, match="twist"):
        kn.ffd_bind(AXIS, MESH, twist=bad)
    with pytest.raises(ValueError, match="twist"):
        kn.ffd_bind(AXIS, MESH).deform(AXIS, np.empty_like(MESH), twist=bad)
    with pytest.raises(ValueError, match="twist"):
        kn.ffd_frames(AXIS, twist=bad)


@pytest.mark.parametrize(
    "bad",
    [np.zeros(2), np.array([1.0, 0.0, 0.0]), np.zeros(3), np.array([0, np.inf, 0.0])],
    ids=["shape", "parallel to the tangent", "zero", "inf"],
)
def test_bad_up(bad):
    with pytest.raises(ValueError, match="up"):
        kn.ffd_bind(AXIS, MESH, up=bad)
    with pytest.raises(ValueError, match="up"):
        kn.ffd_bind(AXIS, MESH).deform(AXIS, np.empty_like(MESH), up=bad)


@pytest.mark.parametrize(
    "bad",
    [
        np.empty((49, 3), np.float32),
        np.empty((50, 3), np.float64),
        np.empty((100, 3), np.float32)[::2],
        "readonly",
    ],
    ids=["rows", "dtype", "non-contiguous", "read-only"],
)
def test_bad_out(bad):
    if isinstance(bad, str):
        bad = np.empty((50, 3), np.float32)
        bad.flags.writeable = False
    with pytest.raises(ValueError, match="out"):
        kn.ffd_bind(AXIS, MESH).deform(AXIS, bad)


def test_deform_with_another_number_of_control_points():
    with pytest.raises(ValueError, match="control_points"):
        kn.ffd_bind(AXIS, MESH).deform(np.vstack([AXIS, [[5.0, 0, 0]]]), np.empty_like(MESH))


def test_bad_curve_parameters_and_samples():
    with pytest.raises(ValueError, match="t"):
        kn.curve_points(AXIS, np.array([0.5, 1.5]))
    with pytest.raises(ValueError, match="t"):
        kn.curve_points(AXIS, np.array([0.5, np.nan]))
    with pytest.raises(ValueError, match="samples"):
        kn.ffd_frames(AXIS, samples=1)


def test_bad_length_pass_input():
    lengths = np.ones(4)
    with pytest.raises(ValueError, match="points"):
        kn.preserve_lengths(AXIS[:, :2].copy(), lengths, 0)
    with pytest.raises(ValueError, match="points"):
        kn.preserve_lengths_from_head(with_value(AXIS, (0, 0), np.nan), lengths)
    with pytest.raises(ValueError, match="rest_lengths"):
        kn.preserve_lengths(AXIS, np.ones(3), 0)
    with pytest.raises(ValueError, match="rest_lengths"):
        kn.preserve_lengths(AXIS, np.array([1.0, 0.0, 1.0, 1.0]), 0)
    with pytest.raises(ValueError, match="moved_index"):
        kn.preserve_lengths(AXIS, lengths, 5)
    with pytest.raises(ValueError, match="arc_length"):
        kn.preserve_lengths_from_head(AXIS, lengths, arc_length=-1.0)
