"""Long strands lose energy and come to rest (issue 9 item 1).

The old length pass moved each joint onto its parent's sphere, root to tip, and took the
velocity from that move: every correction reached the tip as speed, and strands of ten or
more bones kept whipping at metres per second. The solver now projects lengths with both
ends of every segment moving (rod/inextensibility.hpp), and splits substeps while a hanging
chain's tension would outrun them (docs/algorithms.md §3.3)."""

import numpy as np
import pytest
from rod_chain import Chain

GRAVITY = 9.81
DOWN = np.array([0.0, 0.0, -GRAVITY])
STRAND_LENGTH = 0.6


def strand(bones, **params):
    """A 0.6 m strand sticking out horizontally from the head (its rest shape): gravity
    bends it down from the first frame."""
    chain = Chain(bones=bones, length=STRAND_LENGTH / bones, root_offset=(0.0, 0.05, 0.0), **params)
    chain.reset()
    return chain


def kinetic_and_gravitational(chain):
    x = chain.positions()[1:]  # joints after the kinematic root, unit mass each
    v = chain.system.joint_velocities(chain.rod)[1:]
    return 0.5 * float(np.sum(v * v)) + GRAVITY * float(np.sum(x[:, 2]))


def total_energy(chain):
    """Kinetic + gravitational + shape-matching energy as the solver defines it
    (docs/algorithms.md §3.3, "The energy the solver keeps")."""
    return chain.system.energy(chain.rod, DOWN)["total"]


# Heavy damping on long strands once gained a little once the strand hung (0.002 J a frame
# at 32 bones, 0.17 J and 0.12 J at 64): the string mode of a hanging chain, resolved only
# while n g dt² / l < 1 (docs/algorithms.md §3.3). Substeps are now split to keep it there.
CASES = [
    pytest.param(bones, damping, substeps)
    for bones in (16, 32, 64)
    for damping in (0.0, 20.0)
    for substeps in (1, 4)
]


def test_the_shape_matching_energy_is_zero_at_rest_and_grows_when_bent():
    chain = strand(8, stiffness=0.5, damping=2.0)
    at_rest = chain.system.energy(chain.rod, DOWN)
    assert at_rest["kinetic"] == 0.0
    assert abs(at_rest["shape_matching"]) < 1e-9
    for _ in range(6):
        chain.step()
    bent = chain.system.energy(chain.rod, DOWN)
    assert bent["shape_matching"] > 1e-3, "gravity bends the strand away from its shape"
    assert bent["gravitational"] < 0.0
    assert bent["total"] == pytest.approx(
        bent["kinetic"] + bent["gravitational"] + bent["shape_matching"]
    )


@pytest.mark.parametrize(("bones", "damping", "substeps"), CASES)
def test_a_strand_without_bending_stiffness_never_gains_energy(bones, damping, substeps):
    # Kinetic + gravitational + shape-matching energy may only fall, with or without damping
    # (the UI's extremes 0 and 20 1/s), at the fewest and the default substeps. The old
    # solver gained 292 J in one frame at 16 bones, 4871 J at 64.
    chain = strand(bones, stiffness=0.01, damping=damping, substeps=substeps)
    energy = [total_energy(chain)]
    for _ in range(96):
        chain.step()
        energy.append(total_energy(chain))
    gains = np.diff(energy)
    assert gains.max() <= 0.0, f"energy grew by {gains.max():.4g} J in one frame"
    lengths = np.linalg.norm(np.diff(chain.positions(), axis=0), axis=1)
    np.testing.assert_allclose(lengths, STRAND_LENGTH / bones, rtol=1e-5)


# Measured gains per frame at these corners (bones, stiffness, substeps, iterations): not
# solved yet, shown as such.
EXTREMES_STILL_GAINING = {
    (2, 0.01, 64, 1): 0.032,
    (2, 0.01, 64, 64): 8.9e-5,
    (8, 0.01, 64, 64): 0.13,
    (8, 1.0, 64, 1): 0.12,
    (16, 1.0, 64, 64): 0.16,
    (32, 1.0, 64, 64): 0.29,
}
EXTREMES = [
    pytest.param(
        bones,
        stiffness,
        substeps,
        iterations,
        marks=pytest.mark.xfail(
            strict=True, reason="heavily damped strand still gains energy at this corner"
        )
        if (bones, stiffness, substeps, iterations) in EXTREMES_STILL_GAINING
        else (),
    )
    for bones in (2, 8, 16, 32, 64)
    for stiffness in (0.01, 1.0)
    for substeps in (1, 64)
    for iterations in (1, 64)
]
# Round-off of summing the energy of up to 64 joints: far below anything visible.
ROUND_OFF = 1e-5


@pytest.mark.parametrize(("bones", "stiffness", "substeps", "iterations"), EXTREMES)
def test_a_heavily_damped_strand_never_gains_energy_at_the_ui_extremes(
    bones, stiffness, substeps, iterations
):
    # Damping 20 1/s (the UI's top) at every corner of stiffness 0.01-1, substeps 1-64 and
    # iterations 1-64: the strand bends down from its horizontal rest shape and hangs.
    # Motion and height may only lose energy (beyond round-off).
    # (Without damping a stiff strand trades energy with its bending, which this sum leaves
    # out: those settings are covered by the stiffness-0.01 test above.)
    chain = strand(
        bones, stiffness=stiffness, damping=20.0, substeps=substeps, iterations=iterations
    )
    energy = [kinetic_and_gravitational(chain)]
    for _ in range(48):
        chain.step()
        energy.append(kinetic_and_gravitational(chain))
    gains = np.diff(energy)
    assert gains.max() <= ROUND_OFF, f"energy grew by {gains.max():.4g} J in one frame"


@pytest.mark.parametrize("bones", [2, 4, 8, 12, 16, 24, 32, 48, 64])
def test_every_strand_at_the_defaults_comes_to_rest_from_a_horizontal_start(bones):
    # Defaults: stiffness 0.5, damping 2/s, 4 substeps, 1 iteration. Damping 2/s halves a
    # swing's amplitude every 0.7 s: tips whipping at 3-4.5 m/s stay below 1 cm/s from 5.8 s
    # on (measured, 24-64 bones). With 1/s and the tension split they still moved at
    # 1.4-1.8 cm/s after 10 s; the first solver kept 64-bone tips at 8-20 m/s indefinitely.
    chain = strand(bones)
    tip_speeds = []
    for _ in range(24 * 12):
        chain.step()
        tip_speeds.append(np.linalg.norm(chain.system.joint_velocities(chain.rod)[-1]))
    settled = np.array(tip_speeds[24 * 10 :])
    assert settled.max() < 0.01, f"tip still moves at {settled.max():.3f} m/s after 10 s"
    assert max(tip_speeds) > 0.2, "the strand should swing down first"


# Stiff strands without damping: the criterion, not met yet. The solver's shape
# matching is not a gradient step on the energy it is measured with (docs/algorithms.md §3.3,
# "Not yet shown", with the experiment that met it and why it was not kept). Measured gains in
# one frame over 4 s: 1.7 J at the defaults (8 bones), 22 J and 35 J at stiffness 1 and one
# substep, 1.3 J at 64 substeps.
STIFF_UNDAMPED = [
    pytest.param(8, 0.5, 4, id="8 bones, defaults"),
    pytest.param(16, 0.5, 4, id="16 bones, defaults"),
    pytest.param(8, 1.0, 1, id="8 bones, stiffness 1, 1 substep"),
    pytest.param(2, 1.0, 1, id="2 bones, stiffness 1, 1 substep"),
    pytest.param(8, 0.5, 64, id="8 bones, 64 substeps"),
]


@pytest.mark.xfail(strict=True, reason="stiff strands without damping still gain energy")
@pytest.mark.parametrize(("bones", "stiffness", "substeps"), STIFF_UNDAMPED)
def test_a_stiff_strand_without_damping_never_gains_energy(bones, stiffness, substeps):
    chain = strand(bones, stiffness=stiffness, damping=0.0, substeps=substeps)
    energy = [total_energy(chain)]
    for _ in range(96):
        chain.step()
        energy.append(total_energy(chain))
    gains = np.diff(energy)
    assert gains.max() <= ROUND_OFF, f"energy grew by {gains.max():.4g} J in one frame"
