"""Hypothesis strategies that turn a valid argument into a bad, odd or extreme one:
other dtypes, shapes, strides, layouts and types; NaN, inf and huge or tiny values;
near-degenerate point sets; missing or mistyped dict keys; outputs that alias inputs."""

import numpy as np
from hypothesis import strategies as st

SPECIAL = [
    np.nan,
    np.inf,
    -np.inf,
    1e300,
    -1e300,
    3e38,
    -3e38,
    1e200,
    1e10,
    -1e10,
    1e9,
    1e6,
    -1e6,
    1e-300,
    1e-12,
    0.0,
    -0.0,
    -1.0,
    1.0,
    0.5,
]
NON_FINITE = [np.nan, np.inf, -np.inf]
DTYPES = [np.float32, np.float64, np.int32, np.int64, np.uint8, np.bool_, np.complex128, object]
JUNK = [
    None,
    "text",
    b"bytes",
    [],
    {},
    (),
    1,
    -1,
    0,
    2**31,
    -(2**31) - 1,
    2**63,
    1.5,
    np.nan,
    np.inf,
    True,
    object(),
]


def special_float(draw):
    """Mostly the values that break numerics (NaN, inf, huge, tiny), sometimes any float."""
    if draw(st.integers(0, 3)):
        return draw(st.sampled_from(SPECIAL))
    return draw(st.floats(allow_nan=True, allow_infinity=True, width=64))


def mutate_values(draw, arr):
    """Some entries (or all) replaced by special values, or the whole array scaled."""
    out = np.array(arr, copy=True)
    if out.size == 0 or out.dtype.kind not in "fiu":
        return out
    how = draw(st.sampled_from(["some", "all", "scale", "degenerate", "tiny-noise"]))
    with np.errstate(all="ignore"):
        return _mutate_values(draw, out, how)


def _mutate_values(draw, out, how):
    flat = out.reshape(-1)
    if how == "some":
        for _ in range(draw(st.integers(1, 3))):
            i = draw(st.integers(0, flat.size - 1))
            v = special_float(draw)
            flat[i] = (
                v
                if out.dtype.kind == "f"
                else (int(v) if np.isfinite(v) and abs(v) < 2**31 else -1)
            )
    elif how == "all":
        v = special_float(draw)
        if out.dtype.kind == "f":
            flat[:] = v
        else:
            flat[:] = int(v) if np.isfinite(v) and abs(v) < 2**31 else 0
    elif how == "scale" and out.dtype.kind == "f":
        with np.errstate(all="ignore"):
            flat *= draw(
                st.sampled_from([1e300, 1e150, 1e38, 1e12, 1e9, 1e-9, 1e-150, 1e-300, 0.0, -1.0])
            )
    elif how == "degenerate" and out.ndim == 2 and out.dtype.kind == "f" and len(out) > 1:
        # every point (row) on top of the first, or all but one pair coincident
        if draw(st.booleans()):
            out[:] = out[0]
        else:
            i = draw(st.integers(1, len(out) - 1))
            out[i] = out[i - 1]
    elif how == "tiny-noise" and out.dtype.kind == "f" and out.ndim == 2 and len(out) > 1:
        # a near-degenerate polygon: every point within `eps` of the first
        eps = draw(st.sampled_from([1e-3, 1e-6, 1e-7, 1e-9, 1e-12]))
        rng = np.random.default_rng(draw(st.integers(0, 2**16)))
        out[:] = out[0] + eps * rng.standard_normal(out.shape)
    return out


def mutate_array(draw, arr):
    how = draw(
        st.sampled_from(
            [
                "values",
                "values",
                "values",
                "dtype",
                "shape",
                "strides",
                "fortran",
                "readonly",
                "list",
                "junk",
                "empty",
            ]
        )
    )
    if how == "values":
        return mutate_values(draw, arr)
    if how == "dtype":
        dtype = draw(st.sampled_from(DTYPES))
        with np.errstate(all="ignore"):
            try:
                return np.asarray(arr).astype(dtype)
            except (TypeError, ValueError, OverflowError):
                return np.asarray(arr).astype(object)
    if how == "shape":
        a = np.asarray(arr)
        op = draw(
            st.sampled_from(["drop-row", "add-row", "flatten", "add-axis", "transpose", "drop-col"])
        )
        if op == "drop-row" and a.shape and a.shape[0] > 0:
            return np.ascontiguousarray(a[:-1])
        if op == "add-row" and a.shape:
            return np.concatenate([a, a[-1:] if len(a) else np.zeros((1,) + a.shape[1:], a.dtype)])
        if op == "flatten":
            return a.reshape(-1).copy()
        if op == "add-axis":
            return a[None].copy()
        if op == "transpose" and a.ndim == 2:
            return np.ascontiguousarray(a.T)
        if op == "drop-col" and a.ndim == 2 and a.shape[1] > 0:
            return np.ascontiguousarray(a[:, :-1])
        return a.reshape(-1)[:0].copy()
    if how == "strides":
        a = np.asarray(arr)
        if a.ndim == 0:
            return a
        doubled = np.repeat(a, 2, axis=0)
        return doubled[::2]  # same values and shape, not contiguous
    if how == "fortran":
        a = np.asarray(arr)
        return np.asfortranarray(a) if a.ndim == 2 and min(a.shape) > 1 else a[..., None].T.copy()
    if how == "readonly":
        a = np.array(arr, copy=True)
        a.setflags(write=False)
        return a
    if how == "list":
        return np.asarray(arr).tolist()
    if how == "empty":
        a = np.asarray(arr)
        return np.empty((0,) + a.shape[1:], a.dtype)
    return draw(st.sampled_from(JUNK))


def mutate_scalar(draw, value):
    if isinstance(value, bool):
        return draw(
            st.sampled_from(
                [not value, 0, 2, "yes", None, np.bool_(value), np.array([value, value])]
            )
        )
    if isinstance(value, int):
        return draw(
            st.one_of(
                st.sampled_from(
                    [
                        -1,
                        0,
                        1,
                        2**31 - 1,
                        2**31,
                        -(2**31) - 1,
                        2**63,
                        10**6,
                        1.0,
                        2.5,
                        np.int64(value),
                        None,
                        "1",
                    ]
                ),
                st.integers(-100, 100),
            )
        )
    if isinstance(value, float):
        if draw(st.integers(0, 3)):
            return special_float(draw)
        return draw(
            st.sampled_from([None, "1.0", np.float32(value), np.array([value, value]), 1, True])
        )
    if isinstance(value, str):
        return draw(st.sampled_from(["", "flap", "NONE ", "UNDULATE\0", 1, None, value * 100]))
    return draw(st.sampled_from(JUNK))


def mutate(draw, value, depth=0):
    """One mutation of `value`, recursing into dicts and lists (the gait rig)."""
    if isinstance(value, np.ndarray):
        return mutate_array(draw, value)
    if isinstance(value, dict) and depth < 3:
        d = dict(value)
        how = draw(st.sampled_from(["item", "item", "item", "drop", "junk-key", "not-a-dict"]))
        if not d or how == "not-a-dict":
            return draw(st.sampled_from([list(d.values()), None, "dict", 1.0]))
        key = draw(st.sampled_from(sorted(d)))
        if how == "item":
            d[key] = mutate(draw, d[key], depth + 1)
        elif how == "drop":
            del d[key]
        else:
            d[key + "_extra"] = d[key]
        return d
    if isinstance(value, (list, tuple)) and depth < 3:
        items = list(value)
        how = draw(st.sampled_from(["item", "item", "drop", "dup"]))
        if not items:
            return [None]
        i = draw(st.integers(0, len(items) - 1))
        if how == "item":
            items[i] = mutate(draw, items[i], depth + 1)
        elif how == "drop":
            del items[i]
        else:
            items.append(items[i])
        return items
    if value is None:
        return draw(
            st.sampled_from(
                [
                    np.zeros(3),
                    np.array([0.0, 0.0, 1.0]),
                    np.array([np.nan, 0, 1.0]),
                    0.0,
                    "none",
                    np.zeros((2, 3)),
                ]
            )
        )
    return mutate_scalar(draw, value)


def alias(out, source):
    """An array of `out`'s shape and dtype that shares memory with `source`, or None."""
    if not (isinstance(out, np.ndarray) and isinstance(source, np.ndarray)):
        return None
    if out.dtype != source.dtype or source.size < out.size or not source.flags.c_contiguous:
        return None
    return source.reshape(-1)[: out.size].reshape(out.shape)


def is_finite_input(value, depth=0):
    """True when every number in `value` (arrays, dicts, lists) is finite."""
    if depth > 6:
        return True
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc":
            return bool(np.isfinite(value).all())
        if value.dtype.kind == "O":
            return all(is_finite_input(v, depth + 1) for v in value.reshape(-1))
        return True
    if isinstance(value, (float, np.floating)):
        return bool(np.isfinite(value))
    if isinstance(value, dict):
        return all(is_finite_input(v, depth + 1) for v in value.values())
    if isinstance(value, (list, tuple)):
        return all(is_finite_input(v, depth + 1) for v in value)
    return True


def non_finite_outputs(value, where="result", depth=0):
    """Paths of non-finite numbers in a result (arrays, tuples, dicts, bindings)."""
    if depth > 6:
        return []
    if isinstance(value, np.ndarray):
        if value.dtype.kind in "fc" and not np.isfinite(value).all():
            return [where]
        return []
    if isinstance(value, (float, np.floating)):
        return [] if np.isfinite(value) else [where]
    if isinstance(value, dict):
        return [
            p for k, v in value.items() for p in non_finite_outputs(v, f"{where}[{k!r}]", depth + 1)
        ]
    if isinstance(value, (list, tuple)):
        return [
            p
            for i, v in enumerate(value)
            for p in non_finite_outputs(v, f"{where}[{i}]", depth + 1)
        ]
    if type(value).__name__ == "AxisBinding":
        return [
            p
            for k in "tuvw"
            for p in non_finite_outputs(getattr(value, k), f"{where}.{k}", depth + 1)
        ]
    return []


def describe(kwargs):
    """A short, readable account of a case for the crash log."""
    parts = []
    for k, v in kwargs.items():
        if isinstance(v, np.ndarray):
            flags = "C" if v.flags.c_contiguous else ("F" if v.flags.f_contiguous else "strided")
            with np.printoptions(threshold=8, edgeitems=2, precision=3):
                parts.append(
                    f"{k}=array({v.dtype}, {v.shape}, {flags}{'' if v.flags.writeable else ', ro'}, "
                    f"{np.array2string(v.reshape(-1)[:6]) if v.dtype != object else '...'})"
                )
        elif isinstance(v, dict):
            parts.append(
                f"{k}={{{', '.join(f'{kk}: {describe({kk: vv})[len(kk) + 1 :]}' for kk, vv in v.items())}}}"
            )
        else:
            text = repr(v)
            parts.append(f"{k}={text if len(text) < 80 else text[:77] + '...'}")
    return ", ".join(parts)


@st.composite
def junk_array(draw):
    shape = tuple(draw(st.lists(st.integers(0, 6), min_size=0, max_size=3)))
    dtype = draw(st.sampled_from([np.float64, np.float32, np.int32, np.int64, np.bool_]))
    size = int(np.prod(shape)) if shape else 1
    values = [
        special_float(draw) if draw(st.booleans()) else draw(st.floats(-10, 10))
        for _ in range(size)
    ]
    with np.errstate(all="ignore"):
        arr = np.array(values, dtype=np.float64).reshape(shape)
        if dtype != np.float64:
            arr = np.nan_to_num(arr, nan=0, posinf=1, neginf=-1).clip(-1e6, 1e6).astype(dtype)
    return arr


def junk_value():
    leaf = st.one_of(
        junk_array(),
        st.builds(lambda: None),
        st.sampled_from(["", "FLAP", "NONE", "text"]),
        st.integers(-(2**40), 2**40),
        st.sampled_from(SPECIAL),
        st.booleans(),
    )
    return st.one_of(
        leaf,
        st.dictionaries(
            st.sampled_from(["heights", "nx", "x0", "legs", "gaits"]), leaf, max_size=3
        ),
        st.lists(leaf, max_size=3),
    )


def junk_arguments():
    """0 to 6 positional arguments of any kind, for an entry point with no known valid call."""
    return st.lists(junk_value(), max_size=6)
