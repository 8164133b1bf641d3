"""Issue 11 items 1-3: nothing a caller passes to kodawari_native crashes the process or
comes back as NaN/inf. Cases that crashed the old module run in a child process, so a
segfault fails the test instead of ending the run."""

import os
import subprocess
import sys
import textwrap

import kodawari_native as kn
import numpy as np
import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, HERE)
from gait_rigs import horse_rig
from rod_chain import Chain

AXIS = np.column_stack([np.linspace(0.0, 4.0, 5), np.zeros(5), np.zeros(5)])


def run_isolated(code, timeout=120):
    """Runs `code` in a fresh interpreter with this module's import path; returns
    (exit code, stdout + stderr). A negative exit code is a signal (-11 segfault)."""
    env = dict(os.environ, PYTHONPATH=os.pathsep.join([os.path.dirname(kn.__file__), HERE]))
    proc = subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)],
        check=False,
        capture_output=True,
        text=True,
        timeout=timeout,
        env=env,
        cwd=HERE,
    )
    return proc.returncode, proc.stdout + proc.stderr


def ground(**changes):
    g = {"heights": np.zeros(16), "nx": 4, "ny": 4, "x0": -2.0, "y0": -2.0, "cell": 1.0}
    g.update(changes)
    return g


def gait_bake(speed=1.0, ground=None, frames=24):
    return kn.gait_bake(
        horse_rig(),
        kn.gait_horse_table(),
        np.full(frames, speed),
        np.full(frames, -1.0),
        24.0,
        3.0,
        10,
        None,
        ground,
    )


# ---------------------------------------------------------------- item 1: heightfield


@pytest.mark.parametrize(
    "key,value", [("x0", np.nan), ("y0", np.nan), ("x0", np.inf), ("y0", -np.inf), ("cell", np.inf)]
)
def test_gait_bake_refuses_a_non_finite_ground_grid_naming_the_key(key, value):
    code, out = run_isolated(f"""
        import numpy as np
        from test_native_hardening import gait_bake, ground
        try:
            gait_bake(ground=ground({key}=float("{value}")))
        except ValueError as e:
            print("ValueError:", e)
        baked = gait_bake(ground=ground(heights=np.linspace(0.0, 0.2, 16)))
        print("valid ground bakes:", all(np.isfinite(v).all() for v in baked.values()))
        """)
    assert code == 0, f"gait_bake crashed (exit {code}): {out[-400:]}"
    assert f"ValueError: ground['{key}']" in out
    assert "valid ground bakes: True" in out


# ---------------------------------------------------------------- item 2: threads


def test_two_threads_sharing_a_rod_system_get_an_error_never_a_crash():
    code, out = run_isolated("""
        import threading, time
        import numpy as np
        from rod_chain import Chain
        chain = Chain(bones=40)
        chain.reset()
        matrices, gravity = chain.matrices(), np.array([0.0, 0.0, -9.8])
        refused = []
        stop = time.time() + 1.5
        def work(k):
            out = np.zeros((chain.bone_count, 4), np.float32)
            out[:, 0] = 1
            i = 0
            while time.time() < stop:
                i += 1
                try:
                    op = (i + k) % 6
                    if op == 0: chain.system.step(matrices, np.eye(4), None, gravity, i / 24, 1 / 24, out)
                    elif op == 1: chain.system.store_frame(i % 50, out)
                    elif op == 2: chain.system.clear_cache()
                    elif op == 3: chain.system.recall_frame((7 * i) % 50, out, True)
                    elif op == 4: chain.system.cached_rotations(i % 50); chain.system.cached_frames()
                    else: chain.system.reset(matrices, np.eye(4), None, gravity, 0.0, out)
                except RuntimeError as e:
                    refused.append(str(e))
        threads = [threading.Thread(target=work, args=(k,)) for k in range(4)]
        for t in threads: t.start()
        for t in threads: t.join()
        print("refused", len(refused), refused[0] if refused else "")
        for _ in range(5):
            chain.step()
        print("after", bool(np.isfinite(chain.out).all()), bool(np.isfinite(chain.positions()).all()))
        """)
    assert code == 0, f"the process died (exit {code}): {out[-400:]}"
    assert "RodSystem is in use by another thread" in out
    assert "after True True" in out


# ---------------------------------------------------------------- item 3: extreme finite inputs


@pytest.mark.parametrize("speed,name", [(10_000.0, "target_speed"), (1e200, "target_speed")])
def test_gait_bake_refuses_absurd_speeds(speed, name):
    with pytest.raises(ValueError, match=name):
        gait_bake(speed=speed)


@pytest.mark.parametrize("gravity", [(0, 0, -1e300), (1e300, 0, 0)])
def test_rod_gravity_of_1e300_is_refused(gravity):
    chain = Chain()
    with pytest.raises(ValueError, match="gravity"):
        chain.reset(gravity=gravity)
    chain.reset()
    with pytest.raises(ValueError, match="gravity"):
        chain.step(gravity=gravity)
    assert np.isfinite(chain.positions()).all()


def test_rod_wind_of_1e300_is_refused():
    with pytest.raises(ValueError, match="wind"):
        Chain(wind=np.array([1e300, 0.0, 0.0]))


@pytest.mark.parametrize("scale", [1e200, 1e8])
def test_rod_armature_scale_out_of_range_is_refused(scale):
    chain = Chain()
    chain.reset()
    with pytest.raises(ValueError, match="armature_matrix"):
        chain.system.step(
            chain.matrices(),
            np.diag([scale, scale, scale, 1.0]),
            None,
            np.zeros(3),
            0.1,
            1 / 24,
            chain.out,
        )
    assert np.isfinite(chain.positions()).all()


def test_ffd_bind_refuses_vertices_at_3e38():
    vertices = np.full((4, 3), 3e38, dtype=np.float32)
    with pytest.raises(ValueError, match="vertices"):
        kn.ffd_bind(AXIS, vertices)


def test_rod_step_refuses_an_output_that_is_a_view_of_bone_matrices():
    chain = Chain()
    chain.reset()
    matrices = chain.matrices()
    before = matrices.copy()
    view = matrices.reshape(-1)[: chain.bone_count * 4].reshape(chain.bone_count, 4)
    with pytest.raises(ValueError, match="rotations_out.*bone_matrices"):
        chain.system.step(matrices, np.eye(4), None, np.zeros(3), 0.1, 1 / 24, view)
    with pytest.raises(ValueError, match="rotations_out.*bone_matrices"):
        chain.system.reset(matrices, np.eye(4), None, np.zeros(3), 0.0, view)
    np.testing.assert_array_equal(matrices, before)


@pytest.mark.parametrize("key,value", [("nx", "4"), ("nx", 4.5), ("cell", "1"), ("x0", None)])
def test_wrong_types_in_the_ground_dict_name_the_key(key, value):
    with pytest.raises(ValueError, match=rf"ground\['{key}'\]"):
        gait_bake(ground=ground(**{key: value}))


@pytest.mark.parametrize(
    "key,value", [("use_froude", "yes"), ("hysteresis", "0.1"), ("reach", [0.5])]
)
def test_wrong_types_in_the_table_dict_name_the_key(key, value):
    table = kn.gait_horse_table()
    table[key] = value
    with pytest.raises(ValueError, match=rf"table\['{key}'\]"):
        kn.gait_validate_table(table)


def test_wrong_types_in_the_rig_dict_name_the_key():
    rig = horse_rig()
    rig["legs"] = "four legs"
    assert "rig['legs']" in kn.gait_validate_rig(rig)
    rig = horse_rig()
    rig["legs"][2] = [1, 2]
    assert "rig['legs'][2]" in kn.gait_validate_rig(rig)
    with pytest.raises(ValueError, match=r"chain\['lengths'\]"):
        kn.gait_ccd_solve({"lengths": "long"}, np.zeros(2), np.zeros(2), 10, 1e-3)
