"""kodawari_native.view_weights and condition_weights follow the seed's formula exactly."""

import kodawari_native as kn
import numpy as np
import pytest


def seed_formula(directions, influences, view):
    d = view / np.linalg.norm(view)
    w = np.array(
        [
            ((np.dot(di / np.linalg.norm(di), d) + 1) / 2) ** p
            for di, p in zip(directions, influences)
        ]
    )
    s = w.sum()
    if s >= 1:
        w = w / s
        s = 1.0
    return np.concatenate([[1 - s], w])


@pytest.mark.parametrize("m", range(17))
def test_view_weights_match_the_formula_on_random_inputs(m):
    rng = np.random.default_rng(1000 + m)
    for _ in range(20):
        directions = rng.normal(size=(m, 3))
        influences = np.exp(rng.uniform(np.log(0.1), np.log(64.0), size=m))
        view = rng.normal(size=3)
        w = kn.view_weights(directions, influences, view)
        assert w.dtype == np.float64 and w.shape == (m + 1,)
        np.testing.assert_allclose(
            w, seed_formula(directions, influences, view), rtol=1e-12, atol=1e-14
        )
        assert w.sum() == pytest.approx(1.0, abs=1e-12)
        assert (w >= 0).all()


def test_no_keys_gives_the_base_shape_only():
    w = kn.view_weights(np.zeros((0, 3)), np.zeros(0), np.array([0.0, 0.0, 1.0]))
    assert w.tolist() == [1.0]


def test_a_key_facing_away_leaves_the_base_shape_at_full_weight():
    w = kn.view_weights(np.array([[0.0, 0.0, -1.0]]), np.array([4.0]), np.array([0.0, 0.0, 1.0]))
    assert w[0] == 1.0 and w[1] == 0.0


def test_on_a_key_direction_that_key_takes_everything():
    w = kn.view_weights(
        np.array([[1.0, 0, 0], [0, 1.0, 0]]), np.array([2.0, 2.0]), np.array([3.0, 0, 0])
    )
    # Key 0 has weight 1 and key 1 weight 0.5^2: the sum exceeds 1, so both are normalised.
    np.testing.assert_allclose(w, [0.0, 1 / 1.25, 0.25 / 1.25])


def test_condition_weights_are_the_same_formula():
    s = np.array([0.2, 0.9, 1.0])
    p = np.array([1.0, 3.0, 0.5])
    w = s**p
    w = w / w.sum()
    np.testing.assert_allclose(kn.condition_weights(s, p), np.concatenate([[0.0], w]))


@pytest.mark.parametrize(
    "args, message",
    [
        ((np.zeros((1, 3)), np.ones(1), np.array([0.0, 0, 1])), "key_directions must be non-zero"),
        ((np.ones((1, 3)), np.ones(1), np.zeros(3)), "view must be a non-zero direction"),
        ((np.ones((1, 3)), np.zeros(1), np.ones(3)), "influences must be > 0"),
        ((np.ones((2, 3)), np.ones(1), np.ones(3)), "influences must have shape"),
        ((np.ones((1, 3), dtype=np.float32), np.ones(1), np.ones(3)), "float64"),
        ((np.full((1, 3), np.nan), np.ones(1), np.ones(3)), "NaN"),
    ],
)
def test_bad_inputs_raise_a_clear_value_error(args, message):
    with pytest.raises(ValueError, match=message):
        kn.view_weights(*args)
