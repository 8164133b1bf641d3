"""The packaged add-on installs, enables, disables cleanly and enables again."""

import os
import subprocess
import sys
import textwrap

import bpy  # first: importing bpy puts Blender's own modules (addon_utils) on sys.path

# isort: split
import addon_utils
import pytest
from conftest import ADDON_ZIP


def _kodawari_state():
    types = sorted(name for name in dir(bpy.types) if "KODAWARI" in name.upper())
    props = sorted(name for name in dir(bpy.types.Object) if name.startswith("kodawari"))
    handlers = sorted(
        f"{name}:{fn.__module__}"
        for name in dir(bpy.app.handlers)
        if isinstance(getattr(bpy.app.handlers, name), list)
        for fn in getattr(bpy.app.handlers, name)
        if getattr(fn, "__module__", "").split(".")[0] == "kodawari"
        or ".kodawari." in getattr(fn, "__module__", "")
    )
    return types, props, handlers


def test_addon_loads_its_compiled_core(addon):
    from kodawari import native

    assert native.available(), native.error()
    assert native.module().__version__ == "0.1.0"


def test_disable_removes_everything_and_enable_restores_it(addon):
    enabled_state = _kodawari_state()
    assert enabled_state[0], "the enabled add-on registers classes"
    addon_utils.disable("kodawari", default_set=True)
    try:
        assert _kodawari_state() == ([], [], [])
    finally:
        addon_utils.enable("kodawari", default_set=True)
    assert _kodawari_state() == enabled_state


def _run_isolated(script, tmp_path):
    """Runs a script in a fresh Blender process of the same kind as this one,
    with its own empty user folders, and returns the completed process."""
    code = textwrap.dedent(script)
    binary = bpy.app.binary_path or ""
    if os.path.basename(binary).startswith("blender"):
        cmd = [
            binary,
            "-b",
            "--factory-startup",
            "-noaudio",
            "--python-exit-code",
            "1",
            "--python-expr",
            code,
        ]
    else:
        cmd = [sys.executable, "-c", code]
    env = dict(os.environ)
    for name in ("SCRIPTS", "CONFIG", "DATAFILES", "EXTENSIONS"):
        env[f"BLENDER_USER_{name}"] = str(tmp_path / name.lower())
    return subprocess.run(cmd, capture_output=True, text=True, timeout=300, env=env)


def _repack(tmp_path, rename_core=None):
    """A copy of the add-on zip whose compiled core is removed or renamed."""
    import zipfile

    target = tmp_path / "kodawari.zip"
    with zipfile.ZipFile(ADDON_ZIP) as src, zipfile.ZipFile(target, "w") as dst:
        for item in src.infolist():
            name = item.filename
            if "kodawari_native" in name:
                if rename_core is None:
                    continue
                name = "kodawari/" + rename_core
            dst.writestr(name, src.read(item))
    return target


ENABLE_AND_DESCRIBE = """
import bpy, addon_utils
bpy.ops.preferences.addon_install(filepath={zip!r}, overwrite=True)
addon_utils.modules_refresh()
addon_utils.enable("kodawari", default_set=True)
from kodawari import native
assert "kodawari" in bpy.context.preferences.addons, "add-on not enabled"
assert not native.available()
print("REASON:", native.error())
print("PANELS:", sorted(n for n in dir(bpy.types) if n.startswith("KODAWARI_PT")))
print("PROPS:", sorted(n for n in dir(bpy.types.Object) if n.startswith("kodawari")))
addon_utils.disable("kodawari", default_set=True)
print("AFTER:", sorted(n for n in dir(bpy.types) if "KODAWARI" in n.upper()))
"""


@pytest.mark.parametrize(
    "rename_core, reason",
    [
        (None, "is not in this package"),
        ("kodawari_native.cpython-312-x86_64-linux-gnu.so", "built for another Python"),
    ],
)
def test_missing_or_foreign_core_enables_with_a_readable_reason(tmp_path, rename_core, reason):
    repacked = _repack(tmp_path, rename_core)
    done = _run_isolated(ENABLE_AND_DESCRIBE.format(zip=str(repacked)), tmp_path)
    out = done.stdout + done.stderr
    assert done.returncode == 0, out
    assert "Traceback" not in out, out
    assert reason in out
    assert "PANELS: []" in out and "PROPS: []" in out and "AFTER: []" in out


@pytest.mark.skipif(bpy.app.version < (4, 2, 0), reason="extensions exist from Blender 4.2")
def test_installs_and_enables_as_an_extension(tmp_path):
    script = f"""
    import bpy
    bpy.ops.extensions.package_install_files(filepath={ADDON_ZIP!r}, repo="user_default", enable_on_install=True)
    name = "bl_ext.user_default.kodawari"
    assert name in bpy.context.preferences.addons, sorted(bpy.context.preferences.addons.keys())
    import importlib
    native = importlib.import_module(name + ".native")
    assert native.available(), native.error()
    print("EXTENSION OK", native.module().__version__)
    """
    done = _run_isolated(script, tmp_path)
    assert done.returncode == 0 and "EXTENSION OK 0.1.0" in done.stdout, done.stdout + done.stderr
