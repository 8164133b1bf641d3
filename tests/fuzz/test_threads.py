"""Several Python threads on shared kodawari_native objects: never a crash. A RodSystem
refuses a second thread (RuntimeError); an AxisBinding is read-only once bound, so
threads deforming through one binding all get the single-threaded result."""

import threading
import time

import kodawari_native as kn
import numpy as np
from entry_points import _chain_system, _frame_args, axis, mesh


def run_threads(work, count=4):
    errors = []

    def guarded(k):
        try:
            work(k)
        except Exception as exc:  # noqa: BLE001 - reported below, with its type
            errors.append(exc)

    threads = [threading.Thread(target=guarded, args=(k,)) for k in range(count)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    return errors


def test_threads_deforming_through_one_binding_match_one_thread():
    binding = kn.ffd_bind(axis(), mesh(2000))
    moved = axis() * [1.0, 1.5, 1.0]
    expected = np.empty((2000, 3), np.float32)
    binding.deform(moved, expected, threads=1)

    def work(k):
        out = np.empty_like(expected)
        for _ in range(20):
            binding.deform(moved, out, threads=1 + k % 2)
            np.testing.assert_array_equal(out, expected)

    assert run_threads(work) == []


def test_threads_sharing_a_rod_system_are_refused_not_crashed():
    system = _chain_system(bones=40, bone_count=42)
    args = _frame_args(bone_count=42)
    stop = time.monotonic() + 1.5

    def work(k):
        out = args["rotations_out"].copy()
        frame = 0
        while time.monotonic() < stop:
            frame += 1
            try:
                if k % 2:
                    system.step(
                        args["bone_matrices"],
                        np.eye(4),
                        None,
                        args["gravity"],
                        frame / 24,
                        1 / 24,
                        out,
                    )
                    system.store_frame(frame % 40, out)
                else:
                    system.recall_frame(frame % 40, out, True)
                    if frame % 9 == 0:
                        system.clear_cache()
            except RuntimeError as exc:
                assert "in use by another thread" in str(exc)

    assert run_threads(work) == []
    positions = system.joint_positions(0)
    assert np.isfinite(positions).all()


def test_threads_sharing_a_step_ahead_and_its_system_are_refused_not_crashed():
    """Python threads racing start/finish/adopt/store on one RodStepAhead while others step
    the system: each call runs whole or is refused; the system stays usable."""
    system = _chain_system(bones=40, bone_count=42)
    ahead = kn.RodStepAhead(threads=1)
    args = _frame_args(bone_count=42)
    out_args = args.pop("rotations_out")
    stop = time.monotonic() + 1.5

    def work(k):
        out = out_args.copy()
        frame = 0
        while time.monotonic() < stop:
            frame += 1
            try:
                if k == 0:
                    ahead.start(system, rotations=out, **args)
                elif k == 1:
                    if ahead.finish(out):
                        ahead.adopt(system)
                elif k == 2:
                    ahead.store(system, frame % 40)
                else:
                    system.step(rotations_out=out, **args)
            except RuntimeError as exc:
                assert "in use by another thread" in str(exc)

    assert run_threads(work) == []
    out = out_args.copy()
    system.step(rotations_out=out, **args)
    assert np.isfinite(system.joint_positions(0)).all()
