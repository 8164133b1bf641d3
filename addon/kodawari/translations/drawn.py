"""The literal texts the add-on's panels, menus and sidebar draw (text="..." arguments,
labels, iface_("...") calls) and the reports wrapped in tip_("..."), read from their
source with ast so the translation check sees strings added later without running them.

Reports are translated where the message is wrapped in tip_() with str.format
placeholders (an f-string has no fixed text to look up); every add-on source file is
searched for tip_("...") calls (reports(), below), so a new report needs its entry too."""

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


REPORT_CALLS = {"tip_", "pgettext_tip"}


def _parse(path):
    with open(path, encoding="utf-8") as source:
        return ast.parse(source.read())


def sources():
    """Every Python file of the add-on except the translation tables themselves."""
    for folder, _dirs, files in os.walk(PACKAGE):
        if os.path.basename(folder) in ("translations", "__pycache__"):
            continue
        for name in sorted(files):
            if name.endswith(".py"):
                yield os.path.join(folder, name)


def reports():
    """The literal first argument of every tip_("...") call in the add-on (the report and
    error messages: operators' reports, bake errors, problems said once) and bake job titles."""
    found = set()
    for path in sources():
        for node in ast.walk(_parse(path)):
            if isinstance(node, ast.Call):
                name = getattr(node.func, "id", None) or getattr(node.func, "attr", None)
                first = node.args[0] if node.args else None
                if (
                    name in REPORT_CALLS
                    and isinstance(first, ast.Constant)
                    and isinstance(first.value, str)
                    and first.value
                ):
                    found.add(first.value)
            # A bake job's `title = "..."` is said through tip_(job.title) in its reports.
            if (
                isinstance(node, ast.Assign)
                and getattr(node.targets[0], "id", "") == "title"
                and isinstance(node.value, ast.Constant)
                and isinstance(node.value.value, str)
            ):
                found.add(node.value.value)
    return found


def strings():
    found = reports()
    for name in UI_FILES:
        path = os.path.join(PACKAGE, name)
        if os.path.exists(path):
            found |= set(_literals(_parse(path)))
    return found
