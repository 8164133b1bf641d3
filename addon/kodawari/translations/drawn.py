"""The literal texts the add-on's panels, menus and sidebar draw (text="..." arguments,
labels, iface_("...") calls) and the reports wrapped in tip_("..."), read from their
source with ast so the translation check sees strings added later without running them.

Reports are translated only where the operator wraps its message in tip_() with
str.format placeholders (an f-string has no fixed text to look up): fish/apply.py."""

import ast
import os

PACKAGE = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
UI_FILES = (
    "menus.py",
    "sidebar.py",
    "fish/panel.py",
    "hair/panel.py",
    "gait/panel.py",
    "fish/apply.py",
)
TEXT_CALLS = {"iface_", "pgettext_iface", "pgettext", "tip_", "_count"}


def _literals(tree):
    for node in ast.walk(tree):
        if not isinstance(node, ast.Call):
            continue
        for keyword in node.keywords:
            if (
                keyword.arg == "text"
                and isinstance(keyword.value, ast.Constant)
                and keyword.value.value
            ):
                yield keyword.value.value
        name = getattr(node.func, "id", None) or getattr(node.func, "attr", None)
        if name in TEXT_CALLS:
            for arg in node.args:
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str) and arg.value:
                    yield arg.value
    # Menu entries listed as (operator, icon, text, properties) in *_ITEMS tuples (menus.py).
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and getattr(node.targets[0], "id", "").endswith("_ITEMS"):
            for item in getattr(node.value, "elts", []):
                if isinstance(item, ast.Tuple) and len(item.elts) == 4:
                    text = item.elts[2]
                    if isinstance(text, ast.Constant) and isinstance(text.value, str):
                        yield text.value
    # Dictionaries of labels (e.g. LEG_LABELS) are drawn as panel titles: their str values count.
    for node in ast.walk(tree):
        if isinstance(node, ast.Assign) and isinstance(node.value, ast.Dict):
            target = getattr(node.targets[0], "id", "")
            if target.endswith("LABELS"):
                for value in node.value.values:
                    if isinstance(value, ast.Constant) and isinstance(value.value, str):
                        yield value.value


def strings():
    found = set()
    for name in UI_FILES:
        path = os.path.join(PACKAGE, name)
        if os.path.exists(path):
            with open(path, encoding="utf-8") as source:
                found |= set(_literals(ast.parse(source.read())))
    return found
