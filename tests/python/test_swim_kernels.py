"""kodawari_native swim kernels from Python: the math the add-on calls per frame."""

import itertools
import math

import kodawari_native as kn
import numpy as np
import pytest


def _axis(n=8, length=1.0):
    return np.ascontiguousarray(
        np.stack([np.linspace(0, length, n), np.zeros(n), np.zeros(n)], axis=1)
    )


LATERAL = np.array([0.0, 1.0, 0.0])


def test_body_axis_tail_amplitude_and_curve_length():
    rest = _axis(10, 2.0)
    rest_length = kn.curve_length(rest)
    peaks = []
    for phase in np.linspace(0, 2 * math.pi, 200, endpoint=False):
        axis = kn.swim_body_axis(
            rest,
            LATERAL,
            2.0,
            phase,
            wavelength=1.0,
            amplitude=0.1,
            amplitude_head=0.0,
            envelope_start=0.4,
            envelope_power=2.0,
        )
        assert axis[0].tolist() == rest[0].tolist()  # the snout is pinned
        assert kn.curve_length(axis) == pytest.approx(rest_length, rel=1e-6)
        peaks.append(abs(axis[-1, 1]))
    assert max(peaks) == pytest.approx(0.1 * 2.0, rel=0.01)


def test_body_axis_is_deterministic_and_periodic():
    rest = _axis()
    a = kn.swim_body_axis(rest, LATERAL, 1.0, 1.234)
    b = kn.swim_body_axis(rest, LATERAL, 1.0, 1.234)
    c = kn.swim_body_axis(rest, LATERAL, 1.0, 1.234 + 2 * math.pi)
    assert np.array_equal(a, b)
    assert np.allclose(a, c, atol=1e-12)


def test_envelope_grows_from_head_to_tail():
    values = [kn.swim_wave_envelope(s, 0.1, 0.01, 0.3, 2.0) for s in np.linspace(0, 1, 11)]
    assert values[0] == pytest.approx(0.01) and values[-1] == pytest.approx(0.1)
    assert all(b >= a for a, b in itertools.pairwise(values))


def test_accumulated_phase_has_no_jump_when_frequency_steps():
    f = np.r_[np.full(24, 1.0), np.full(24, 3.0)]
    phase = kn.swim_accumulate_phase(f, 1 / 24)
    steps = np.diff(phase)
    assert steps.max() <= 2 * math.pi * 3.0 / 24 + 1e-12
    assert phase[23] == pytest.approx(2 * math.pi * 1.0 * 23 / 24)


def test_speeds():
    assert kn.swim_speed("BAINBRIDGE", 0.3, 6.0, 0.1, 0.3) == pytest.approx(0.25 * 0.3 * (18 - 4))
    assert kn.swim_speed("STROUHAL", 1.0, 2.0, 0.1, 0.25) == pytest.approx(2.0 * 0.2 / 0.25)
    assert kn.swim_speed("NONE", 1.0, 2.0, 0.1, 0.25) == 0.0
    with pytest.raises(ValueError, match="mode"):
        kn.swim_speed("WARP", 1.0, 2.0, 0.1, 0.25)


def test_fin_axis_motions():
    rest = np.array(
        [[0, 0, 0], [0, 0.02, 0], [0, 0.04, 0], [0, 0.5, 0], [0, 1.0, 0]], dtype=np.float64
    )
    frame = (np.array([1.0, 0, 0]), np.array([0, 1.0, 0]), np.array([0, 0, 1.0]))
    for motion in ("FLAP", "UP_DOWN", "TWIST", "UNDULATE"):
        points, twist = kn.swim_fin_axis(rest, *frame, motion, 0.4, math.pi / 2)
        assert points.shape == (5, 3) and twist.shape == (5,)
    points, _ = kn.swim_fin_axis(rest, *frame, "FLAP", 0.4, math.pi / 2)
    assert np.array_equal(points[:3], rest[:3])
    with pytest.raises(ValueError, match="motion"):
        kn.swim_fin_axis(rest, *frame, "WIGGLE", 0.4, 0.0)
    stroke = kn.swim_flap_stroke_direction(np.array([0, 1.0, 0]), *frame)
    assert np.allclose(np.abs(stroke), [1, 0, 0])


@pytest.mark.parametrize(
    "kwargs,name",
    [
        ({"rest_points": np.zeros((5, 3), dtype=np.float32)}, "rest_points"),
        ({"bend_direction": np.zeros(3)}, "bend_direction"),
        ({"wavelength": 0.0}, "wavelength"),
        ({"body_length": -1.0}, "body_length"),
        ({"phase": float("nan")}, "phase"),
    ],
)
def test_body_axis_rejects_bad_input_naming_it(kwargs, name):
    args = {"rest_points": _axis(), "bend_direction": LATERAL, "body_length": 1.0, "phase": 0.0}
    args.update(kwargs)
    with pytest.raises(ValueError, match=name):
        kn.swim_body_axis(**args)
