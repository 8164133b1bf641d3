"""The frame cache keeps to a memory budget and stays exact (issue 9 item 5).

Unbounded, the cache held every frame's full state: about 2.6 MB per frame at 16,000 bones,
26 GB after 10,000 frames. With a budget it thins to checkpoints; a dropped frame is
recomputed from the nearest checkpoint before it, bit for bit."""

import kodawari_native as kn
import numpy as np
from rod_chain import no_keys

RODS, BONES = 1000, 16  # 16,000 rod bones
# 48 MB: about a dozen frames of this system (4.0 MB each since the state also carries the
# energy budget's window, docs/algorithms.md §3.3; 2.7 MB before, with a 32 MB budget).
BUDGET = 48 << 20


def _system():
    bone_count = 1 + RODS * BONES
    system = kn.RodSystem(bone_count, 0)
    offsets = np.array([(0.0, 0.1, 0.0)] + [(0.0, 0.03, 0.0)] * BONES)
    rest = np.tile([1.0, 0.0, 0.0, 0.0], (BONES, 1))
    for r in range(RODS):
        system.add_rod(
            0,
            0,
            np.arange(1 + r * BONES, 1 + (r + 1) * BONES, dtype=np.int32),
            offsets,
            rest,
            wind=np.zeros(3),
            **no_keys(),
        )
    return system, bone_count


def _matrices(bone_count, frame):
    """The head sways; every other bone at identity."""
    m = np.tile(np.eye(4, dtype=np.float32), (bone_count, 1, 1))
    m[0, 3, 0] = 0.2 * np.sin(frame / 5.0)  # column-major: translation in the last row
    m[0, 3, 2] = 0.1 * np.sin(frame / 3.0)
    return m.reshape(bone_count, 16)


GRAVITY = np.array([0.0, 0.0, -9.81])


def _step(system, bone_count, frame, out):
    system.step(_matrices(bone_count, frame), np.eye(4), None, GRAVITY, frame / 24, 1 / 24, out)


def test_the_cache_keeps_its_budget_over_10000_frames_of_16000_bones_and_scrubbing_back_is_exact():
    system, bone_count = _system()
    system.cache_budget = BUDGET
    out = np.zeros((bone_count, 4), np.float32)
    system.reset(_matrices(bone_count, 1), np.eye(4), None, GRAVITY, 1 / 24, out)
    system.store_frame(1, out)
    played = {}
    simulated = 40
    for frame in range(2, simulated + 1):  # simulated frames, the head swaying
        _step(system, bone_count, frame, out)
        system.store_frame(frame, out)
        played[frame] = out.copy()
        assert system.cache_bytes <= BUDGET
    entry = system.cache_bytes / len(system.cached_frames())
    for frame in range(simulated + 1, 10_001):  # 10,000 frames in all (the state held still)
        system.store_frame(frame, out)
        assert system.cache_bytes <= BUDGET, frame
    assert 10_000 * entry > 100 * BUDGET, "unbounded, the cache would have held gigabytes"
    frames = system.cached_frames()
    assert frames[-1] == 10_000 and len(frames) <= BUDGET // entry

    # Scrub back to played frames the budget dropped: recompute from the nearest checkpoint.
    for target in (37, 19):
        assert not system.recall_frame(target, None, True), (
            "the budget should have dropped this frame"
        )
        start = system.latest_cached_frame_before(target)
        assert start is not None and start < target
        assert system.recall_frame(start, None, True)
        for frame in range(start + 1, target + 1):
            _step(system, bone_count, frame, out)
        np.testing.assert_array_equal(out, played[target])
