"""A stiff rod holds its keyed shape (issue 9 item 1: the energy budget must not cost it).

The sample character's rabbit ears: 35 cm of 5 bones at stiffness 0.9 and 6 iterations,
keyed 15° from vertical. The solver's own bending stiffness is far below the stiffness the
energy measures (docs/algorithms.md §3.3); the energy budget keeps the ear from sagging below
what that stiffness allows. Before it, the ear leaned 18° with 6 iterations and 61° with one."""

import numpy as np
import pytest
from rod_chain import Chain, axis_angle_quat, quat_to_matrix

BONES, LENGTH = 5, 0.07
KEYED = 15.0  # degrees from vertical
CAMERA = (0.0, -5.0, 0.0)  # in front of the head: the view key is the one that counts


def ear(iterations):
    # The chain leaves the head along +Y; the key turns its first bone up to 15° from vertical.
    up = axis_angle_quat((1, 0, 0), np.radians(90 - KEYED))
    shape = [up] + [np.array([1.0, 0.0, 0.0, 0.0])] * (BONES - 1)
    chain = Chain(
        bones=BONES,
        length=LENGTH,
        root_offset=(0.0, 0.05, 0.0),
        stiffness=0.9,
        iterations=iterations,
        damping=1.5,
        keys=[dict(condition=0, direction=(0.0, -1.0, 0.0), shape=shape, influence=0.01)],
    )
    chain.reset(camera=CAMERA)
    return chain


def lean(chain):
    """The ear's root-to-tip angle from vertical, degrees."""
    p = chain.positions()
    d = p[-1] - p[0]
    return np.degrees(np.arccos(d[2] / np.linalg.norm(d)))


@pytest.mark.parametrize(("iterations", "tolerance"), [(6, 1.0), (1, 3.0)])
def test_a_stiff_ear_holds_its_keyed_lean(iterations, tolerance):
    # Measured: 15.2° (6 iterations) and 17.3° (one); before the budget 18.1° and 60.7°.
    chain = ear(iterations)
    for _ in range(48):
        chain.step(camera=CAMERA)
    assert abs(lean(chain) - KEYED) < tolerance, f"the ear leans {lean(chain):.1f}°, keyed {KEYED}°"


def test_a_stiff_ear_swings_with_a_nod_and_returns_to_its_lean():
    # The head nods ±30° over a second and stops: the ear moves with it, swings on after the
    # stop and comes back to within 2° of its keyed lean (measured 16.4°; before the budget
    # 18.0°, 3° off).
    chain = ear(6)
    for _ in range(48):
        chain.step(camera=CAMERA)
    for frame in range(1, 25):
        nod = np.radians(30) * np.sin(2 * np.pi * frame / 24)
        chain.head_rotation = quat_to_matrix(axis_angle_quat((1, 0, 0), nod))
        chain.step(camera=CAMERA)
    stopped = chain.positions()[-1]
    tips = []
    for _ in range(24 * 4):
        chain.step(camera=CAMERA)
        tips.append(chain.positions()[-1])
    swing = np.linalg.norm(np.array(tips[:24]) - stopped, axis=1).max()
    assert swing > 0.02, f"the ear tip moved only {swing * 100:.1f} cm after the nod"
    assert abs(lean(chain) - KEYED) < 2.0, f"the ear leans {lean(chain):.1f}° after the nod"
    speeds = np.linalg.norm(np.diff(np.array(tips[-24:]), axis=0), axis=1) * 24
    assert speeds.max() < 0.01, "the ear should be at rest again"
