"""Rig descriptions for the native gait tests: the same Thoroughbred proportions the
demo builds in Blender (4 bones per leg, moving scapula), facing -Y, z up, feet at z=0."""

import math

import numpy as np

# Absolute rest angles from straight down, degrees, positive = tip backward (seed 3.2).
FORE = (
    (0.45, -35.0),
    (0.30, 45.0),
    (0.40, -5.0),
    (0.45, 10.0),
)  # scapula, humerus, radius, cannon+hoof
HIND = (
    (0.40, 60.0),
    (0.42, -25.0),
    (0.40, 35.0),
    (0.50, -5.0),
)  # pelvis, femur, tibia, cannon+hoof
# Joint ranges in the seed's convention (each bone relative to its parent, the first
# relative to straight down), widened where the seed's snapshot ranges cannot reach
# the seed's own +-0.8 m (see README).
FORE_LIMITS = ((-55, -15), (60, 100), (-135, -5), (0, 120))
HIND_LIMITS = ((40, 75), (-125, -55), (10, 125), (-135, 0))
STIFFNESS = (0.1, 0.3, 0.5, 1.0)


def leg(root, bones, limits, stiffness=STIFFNESS):
    """heads/tail in armature space from (length, absolute angle) down the leg."""
    heads = [np.array(root, dtype=float)]
    previous = 0.0
    lo, hi = [], []
    for (length, angle), (a, b) in zip(bones, limits):
        rad = math.radians(angle)
        # Forward is -Y: a backward tip (positive angle) moves towards +Y.
        step = np.array([0.0, length * math.sin(rad), -length * math.cos(rad)])
        heads.append(heads[-1] + step)
        relative = angle - previous
        lo.append(math.radians(a - relative))
        hi.append(math.radians(b - relative))
        previous = angle
    return {
        "heads": np.array(heads[:-1]),
        "tail": heads[-1],
        "limit_min": np.array(lo),
        "limit_max": np.array(hi),
        "stiffness": np.array(stiffness, dtype=float),
    }


def _drop(bones):
    return sum(length * math.cos(math.radians(angle)) for length, angle in bones)


def horse_rig():
    fore_z, hind_z = _drop(FORE), _drop(HIND)
    legs = [
        leg((0.12, -0.55, fore_z), FORE, FORE_LIMITS),
        leg((-0.12, -0.55, fore_z), FORE, FORE_LIMITS),
        leg((0.14, 0.55, hind_z), HIND, HIND_LIMITS),
        leg((-0.14, 0.55, hind_z), HIND, HIND_LIMITS),
    ]
    return {
        "forward": np.array([0.0, -1.0, 0.0]),
        "body_head": np.array([0.0, 0.0, 1.4]),
        # the body bone points forward (-Y): its rest matrix's columns are its X, Y, Z axes
        "body_rest": np.array([[1.0, 0, 0], [0, -1.0, 0], [0, 0, -1.0]]),
        "legs": legs,
    }


def neutral(rig):
    return np.array([np.dot(leg["tail"] - leg["heads"][0], rig["forward"]) for leg in rig["legs"]])


def limits(rig):
    return (
        np.concatenate([leg["limit_min"] for leg in rig["legs"]]),
        np.concatenate([leg["limit_max"] for leg in rig["legs"]]),
    )
