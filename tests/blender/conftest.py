"""Blender test fixtures, shared by every Blender (the real program and bpy modules).

The add-on under test is the packaged dist/kodawari.zip, installed the way a user
installs it, into a throw-away user scripts folder (BLENDER_USER_SCRIPTS, set by
tools/run_tests.sh before Blender starts)."""

import os
import sys

import bpy  # first: importing bpy puts Blender's own modules (addon_utils) on sys.path
import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))

sys.path.insert(0, os.path.join(ROOT, "tools"))
from blender_install_addon import ADDON_ZIP, install_addon


@pytest.fixture(scope="session", autouse=True)
def addon():
    install_addon()
    import kodawari

    yield kodawari


@pytest.fixture
def empty_scene(addon):
    """A fresh empty file (keeps preferences, so the add-on stays enabled)."""
    bpy.ops.wm.read_homefile(use_empty=True, use_factory_startup=True)
    yield bpy.context.scene
