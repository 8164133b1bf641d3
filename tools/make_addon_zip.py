"""Packs addon/kodawari (with the compiled core copied in by `make native`) into
dist/kodawari.zip, top folder `kodawari/`: installs as a legacy add-on in
Blender 3.4+ and, through blender_manifest.toml, as an extension in 4.2+."""

import glob
import os
import sys
import zipfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SOURCE = os.path.join(ROOT, "addon", "kodawari")
TARGET = os.path.join(ROOT, "dist", "kodawari.zip")


def main():
    if not glob.glob(os.path.join(SOURCE, "kodawari_native*.so")):
        sys.exit(
            "make_addon_zip: addon/kodawari has no compiled kodawari_native; run `make native` first"
        )
    os.makedirs(os.path.dirname(TARGET), exist_ok=True)
    count = 0
    with zipfile.ZipFile(TARGET, "w", zipfile.ZIP_DEFLATED) as archive:
        for folder, dirs, files in os.walk(SOURCE):
            dirs[:] = sorted(d for d in dirs if d != "__pycache__")
            for name in sorted(files):
                if name.endswith((".pyc", ".blend1")):
                    continue
                path = os.path.join(folder, name)
                archive.write(path, os.path.join("kodawari", os.path.relpath(path, SOURCE)))
                count += 1
    print(f"wrote {os.path.relpath(TARGET, ROOT)} ({count} files)")


if __name__ == "__main__":
    main()
