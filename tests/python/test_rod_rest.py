"""A strand at rest sleeps, and wakes for whatever could move it (docs/algorithms.md §3.3).

Once the energy budget has put a strand back where its window began with the head still, the
chain rests where its energy allows and its substeps are skipped (a scene of resting hair
costs a tenth of the solver's time). Anything that could move it must wake it: the head
moving, gravity changing, a collider reaching a joint."""

import kodawari_native as kn
import numpy as np
from rod_chain import Chain, no_keys, pack_matrices

RADIUS = 0.1  # the collider sphere


class ChainWithHand(Chain):
    """The test chain plus a sphere collider on a separate 'hand' bone the test moves."""

    def __init__(self, **params):
        self.hand = np.array([0.6, 0.2, -0.35])
        sphere = (
            np.array([0], np.int32),  # bone index, replaced below
            np.array([0], np.int32),
            np.zeros((1, 3)),
            np.array([RADIUS]),
            np.zeros(1),
        )
        super().__init__(bones=8, length=0.075, root_offset=(0.0, 0.05, 0.0), **params)
        self.bone_count += 1  # not known to the rod system's rods: only the collider uses it
        # Rebuild the system with room for the hand bone, then the same rod and the collider.
        self.system = kn.RodSystem(self.bone_count, 0)
        offsets = np.array([(0.0, 0.05, 0.0)] + [(0.0, 0.075, 0.0)] * self.n)
        self.rod = self.system.add_rod(
            0,
            0,
            np.arange(1, self.n + 1, dtype=np.int32),
            offsets,
            np.tile([1.0, 0, 0, 0], (self.n, 1)),
            wind=np.zeros(3),
            **no_keys(),
        )
        hand_bone = np.array([self.n + 1], np.int32)
        self.system.set_colliders(hand_bone, *sphere[1:])
        self.out = np.zeros((self.bone_count, 4), dtype=np.float32)
        self.out[:, 0] = 1

    def matrices(self):
        rotations = np.tile(np.eye(3), (self.bone_count, 1, 1))
        positions = np.zeros((self.bone_count, 3))
        rotations[0] = self.head_rotation
        positions[0] = self.head_position
        positions[-1] = self.hand
        return pack_matrices(rotations, positions)


def rested(chain, seconds=10, **step):
    chain.reset()
    for _ in range(24 * seconds):
        chain.step(**step)
    return chain.positions()


def test_a_resting_strand_wakes_when_gravity_turns():
    # Gravity turns 90° (a character lying down, a scene's gravity animated): the strand, long
    # at rest, must fall the new way. Measured: the tip moves 0.55 m in the second after.
    chain = Chain(bones=8, length=0.075, root_offset=(0.0, 0.05, 0.0))
    before = rested(chain)
    for _ in range(24):
        chain.step(gravity=(0.0, -9.81, 0.0))
    moved = np.linalg.norm(chain.positions()[-1] - before[-1])
    assert moved > 0.1, f"the tip moved only {moved * 100:.1f} cm after gravity turned"


def test_a_resting_strand_wakes_when_a_collider_reaches_it():
    # A sphere on a hand bone sweeps into the hanging strand: no joint may end a frame inside it
    # (the rod's radius, 1 cm, added), and the strand must give way.
    chain = ChainWithHand()
    before = rested(chain)
    closest = np.inf
    for frame in range(1, 25):
        chain.hand = np.array([0.6 - 0.6 * frame / 24, 0.2, -0.35])
        chain.step()
        closest = min(closest, np.linalg.norm(chain.positions() - chain.hand, axis=1).min())
    assert closest >= RADIUS + 0.01 - 1e-6, f"a joint ended {closest:.4f} m from the centre"
    moved = np.abs(chain.positions() - before).max()
    assert moved > 0.05, f"the strand moved only {moved * 100:.1f} cm out of the sphere's way"
