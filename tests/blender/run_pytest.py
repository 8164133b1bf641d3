"""Runs pytest inside the real Blender program:
    blender -b --factory-startup -noaudio --python-exit-code 1 --python tests/blender/run_pytest.py -- ARGS
The same test files also run under the `bpy` module with plain `python -m pytest`."""

import sys

import pytest

args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else ["tests/blender"]
sys.exit(int(pytest.main(["-p", "no:cacheprovider", *args])))
