"""The compiled module loads and identifies its build."""

import sys

import kodawari_native


def test_version_matches_the_addon():
    assert kodawari_native.__version__ == "0.1.0"


def test_built_for_this_python():
    assert sys.version_info[0] * 100 + sys.version_info[1] == kodawari_native.PYTHON_ABI
