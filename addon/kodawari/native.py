"""Guarded import of the compiled core, with a readable reason when it cannot load.

The add-on must enable even when `kodawari_native` is missing or was built for
another Python, and say why instead of raising a traceback.
"""

import glob
import os
import sys

ADDON_VERSION = "0.1.0"

_module = None
_error = None


def _expected_tag():
    return f"cpython-{sys.version_info[0]}{sys.version_info[1]}"


def _diagnose(exc):
    here = os.path.dirname(__file__)
    builds = sorted(os.path.basename(p) for p in glob.glob(os.path.join(here, "kodawari_native*")))
    want = f"Python {sys.version_info[0]}.{sys.version_info[1]} ({_expected_tag()})"
    if not builds:
        return (
            f"Kodawari's compiled core (kodawari_native) is not in this package. "
            f"Install a dist/kodawari.zip built with `make addon` for {want}."
        )
    if not any(_expected_tag() in b for b in builds):
        return (
            f"Kodawari's compiled core was built for another Python: found {', '.join(builds)}, "
            f"this Blender runs {want}. Rebuild with `make addon` for {want}."
        )
    return f"Kodawari's compiled core failed to load ({', '.join(builds)}): {exc}"


def load():
    """Import the core once; return it, or None with `error()` saying why."""
    global _module, _error
    if _module is not None or _error is not None:
        return _module
    try:
        try:
            from . import kodawari_native as module
        except ImportError:
            import kodawari_native as module  # a `pip install .` build
    except ImportError as exc:
        _error = _diagnose(exc)
        return None
    if getattr(module, "__version__", None) != ADDON_VERSION:
        _error = (
            f"Kodawari's compiled core is version {getattr(module, '__version__', '?')}, "
            f"the add-on is {ADDON_VERSION}: install a matching build (`make addon`)."
        )
        return None
    _module = module
    return _module


def module():
    """The loaded core; only called by features, which register only when it loaded."""
    if _module is None:
        raise RuntimeError(_error or "kodawari_native not loaded")
    return _module


def available():
    return load() is not None


def error():
    load()
    return _error
