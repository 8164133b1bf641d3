"""List the Kodawari UI strings that have no translation yet, one per line.

Run inside any supported Blender, from the repository root:
    blender -b --factory-startup --python tools/i18n_missing.py -- [locale]      # default ja_JP
    python tools/i18n_missing.py [locale]                                        # bpy module
It installs dist/kodawari.zip into throw-away folders (like the tests) and walks the
registered classes' RNA (every operator, setting, enum item, panel and menu) plus the
literal texts the panels, menus and sidebar draw. Exit code 1 when something is missing."""

import json
import os
import sys

import bpy  # noqa: F401  (first: puts Blender's modules on sys.path)

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "tools"))


def main(argv):
    locale = argv[0] if argv else "ja_JP"
    from blender_install_addon import install_addon

    install_addon()
    from kodawari import translations

    missing = translations.missing(locale)
    for msgid in missing:
        print(json.dumps(msgid, ensure_ascii=False))
    print(f"{len(missing)} string(s) without a {locale} translation", file=sys.stderr)
    for msgid in translations.unused(locale):
        print(
            f"unused entry (safe to delete): {json.dumps(msgid, ensure_ascii=False)}",
            file=sys.stderr,
        )
    return 1 if missing else 0


if __name__ == "__main__":
    args = sys.argv[sys.argv.index("--") + 1 :] if "--" in sys.argv else sys.argv[1:]
    sys.exit(main(args))
