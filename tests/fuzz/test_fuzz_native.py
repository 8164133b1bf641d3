"""The fuzz tier: every kodawari_native entry point, called with its valid arguments
after hypothesis mutated some of them (tests/fuzz/mutations.py). A case passes when
the call
  - returns, and the result (and the outputs it wrote) is finite whenever every input
    number was finite; or
  - raises ValueError, TypeError or IndexError whose message names an argument (or a
    dict key of one): "control_points must ...", "ground['cell'] ...".
Anything else fails: another exception, a non-finite result from finite inputs, a
crash (tools/run_fuzz.py runs this file in a child process and reports the case that
was running), or a case that takes longer than CASE_TIMEOUT seconds.
Reproducible: each entry point's cases come from a fixed seed (its name's CRC-32)."""

import faulthandler
import os
import re
import warnings
import zlib

import pytest
from conftest import CASES
from entry_points import TARGETS, all_targets, public_entry_points
from hypothesis import HealthCheck, Phase, given, seed, settings
from hypothesis import strategies as st
from mutations import alias, describe, is_finite_input, junk_arguments, mutate, non_finite_outputs

CASE_TIMEOUT = 30
LOG = os.environ.get("KODAWARI_FUZZ_LOG")
# Cases per entry point: Target.examples x SCALE (2: ~7,000 cases, ~40 s of CPU; set
# KODAWARI_FUZZ_SCALE=20 for a longer hunt).
SCALE = float(os.environ.get("KODAWARI_FUZZ_SCALE", "2"))
ALLOWED = (ValueError, TypeError, IndexError)
# Open for the whole run: after a crash the parent reads the case that was running.
_log = open(LOG, "w", buffering=1) if LOG else None


def dict_keys(value, depth=0):
    """Every key of the dicts inside `value` (dicts in lists in dicts...)."""
    if depth > 4:
        return set()
    if isinstance(value, dict):
        return {str(k) for k in value} | dict_keys(list(value.values()), depth + 1)
    if isinstance(value, (list, tuple)):
        return set().union(*(dict_keys(v, depth + 1) for v in value)) if value else set()
    return set()


def names_an_argument(message, target, kwargs):
    if (
        "incompatible function arguments" in message
        or "incompatible constructor arguments" in message
    ):
        return True  # pybind11 lists the signature, every argument by name
    words = set(kwargs) | set(target.extra_names)
    words |= dict_keys(list(kwargs.values()))  # rig['legs'][0]['limit_min'] names limit_min
    words |= {w.replace("_", " ") for w in words}
    words |= {
        w[:-1] for w in words if w.endswith("s") and len(w) > 3
    }  # "a key shape ..." names key_shapes
    return any(re.search(rf"(?<![A-Za-z]){re.escape(w)}", message) for w in words if w)


def check_case(target, kwargs):
    finite_in = is_finite_input(kwargs)
    if _log:
        _log.write(f"{target.name}({describe(kwargs)})\n")
    faulthandler.dump_traceback_later(CASE_TIMEOUT, exit=True)
    try:
        result = target.call(*kwargs.values()) if target.generic else target.call(**kwargs)
    except ALLOWED as exc:
        message = str(exc)
        assert names_an_argument(message, target, kwargs), (
            f"{target.name}: {type(exc).__name__} does not name an argument: {message!r}"
        )
        return
    except Exception as exc:  # noqa: BLE001 - the point is to catch what should not happen
        pytest.fail(
            f"{target.name}: {type(exc).__name__} (only ValueError/TypeError/IndexError allowed): {exc}"
        )
    finally:
        faulthandler.cancel_dump_traceback_later()
    if finite_in:
        bad = non_finite_outputs(result) + [
            name for name in target.outputs if name in kwargs and non_finite_outputs(kwargs[name])
        ]
        assert not bad, f"{target.name}: finite inputs gave non-finite {bad}"


ALL_TARGETS = all_targets()


@pytest.mark.parametrize("target", ALL_TARGETS, ids=[t.name for t in ALL_TARGETS])
def test_entry_point(target):
    @seed(zlib.crc32(target.name.encode()))
    @settings(
        max_examples=max(1, int(target.examples * SCALE)),
        deadline=None,
        database=None,
        phases=[Phase.explicit, Phase.generate, Phase.shrink],
        suppress_health_check=list(HealthCheck),
    )
    @given(st.data())
    def run(data):
        CASES["count"] += 1
        if target.generic:
            args = data.draw(junk_arguments(), label="arguments")
            check_case(target, {f"arg{i}": a for i, a in enumerate(args)})
            return
        kwargs = target.make_args()
        names = sorted(kwargs)
        if names:
            for name in data.draw(
                st.sets(st.sampled_from(names), min_size=0, max_size=min(3, len(names))),
                label="mutated",
            ):
                kwargs[name] = mutate(data.draw, kwargs[name])
        for out_name, in_name in target.alias:
            if data.draw(st.integers(0, 3), label="alias") == 0:
                shared = alias(kwargs.get(out_name), kwargs.get(in_name))
                if shared is not None:
                    kwargs[out_name] = shared
        check_case(target, kwargs)

    run()


@pytest.mark.parametrize("target", TARGETS, ids=[t.name for t in TARGETS])
def test_the_valid_call_succeeds(target):
    """The unmutated call must work, else every case would stop at the same first error
    (e.g. an argument without a keyword name) and the fuzzing would reach nothing."""
    kwargs = target.make_args()
    if target.name == "AxisBinding":
        return  # no constructor from Python: bindings come from ffd_bind
    result = target.call(**kwargs)
    assert not non_finite_outputs(result), f"{target.name}: the valid call gave non-finite results"


def test_every_entry_point_is_fuzzed():
    """Every public entry point has a target; those only fuzzed generically (random
    positional arguments, no valid call to mutate) are named in a warning: give them a
    valid call in entry_points.py to fuzz them in depth."""
    covered = {t.name for t in ALL_TARGETS}
    missing = [n for n in public_entry_points() if n not in covered]
    assert not missing, (
        f"no way to reach these entry points (add them to entry_points.py): {missing}"
    )
    generic = [t.name for t in ALL_TARGETS if t.generic]
    if generic:
        warnings.warn(f"fuzzed with random arguments only: {generic}", stacklevel=1)
