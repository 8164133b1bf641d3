"""One version everywhere: a mismatch makes the add-on refuse its own core."""

import ast
import re
import tomllib
from pathlib import Path

import kodawari_native

ROOT = Path(__file__).resolve().parents[2]
ADDON = ROOT / "addon" / "kodawari"


def test_every_file_states_the_same_version():
    cmake = re.search(
        r"project\(kodawari VERSION (\S+)", (ROOT / "CMakeLists.txt").read_text()
    ).group(1)
    pyproject = tomllib.loads((ROOT / "pyproject.toml").read_text())["project"]["version"]
    manifest = tomllib.loads((ADDON / "blender_manifest.toml").read_text())["version"]
    init = ast.parse((ADDON / "__init__.py").read_text())
    bl_info = next(
        ast.literal_eval(n.value)
        for n in init.body
        if isinstance(n, ast.Assign) and n.targets[0].id == "bl_info"
    )
    native_py = re.search(r'ADDON_VERSION = "(\S+)"', (ADDON / "native.py").read_text()).group(1)
    versions = {
        "CMakeLists.txt": cmake,
        "pyproject.toml": pyproject,
        "blender_manifest.toml": manifest,
        "bl_info": ".".join(map(str, bl_info["version"])),
        "native.py": native_py,
        "kodawari_native": kodawari_native.__version__,
    }
    assert len(set(versions.values())) == 1, versions
