"""Installs dist/kodawari.zip as a user would and enables it; importable, or run
first on a Blender command line:  blender -b --python tools/blender_install_addon.py --python X.py
Run it under throw-away BLENDER_USER_* folders (tools/*.sh do) so nothing leaks."""

import os

import bpy  # first: importing bpy puts Blender's own modules (addon_utils) on sys.path

# isort: split
import addon_utils

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
ADDON_ZIP = os.environ.get("KODAWARI_ADDON_ZIP", os.path.join(ROOT, "dist", "kodawari.zip"))


def _raise(exc):
    raise exc


def install_addon(zip_path=ADDON_ZIP):
    if not os.path.isfile(zip_path):
        raise RuntimeError(f"{zip_path} is missing: run `make addon` first")
    bpy.ops.preferences.addon_install(filepath=zip_path, overwrite=True)
    addon_utils.modules_refresh()
    addon_utils.enable("kodawari", default_set=True, handle_error=_raise)
    if "kodawari" not in bpy.context.preferences.addons:
        raise RuntimeError("the kodawari add-on did not enable")
    from kodawari import native

    if not native.available():
        raise RuntimeError(native.error())


if __name__ == "__main__":
    install_addon()
