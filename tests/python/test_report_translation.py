"""Reports (operators' self.report, bake errors, problems said once) are translatable:
their text is a fixed msgid wrapped in tip_() with str.format for the variable parts, and
every such msgid has a Japanese entry. Read from the add-on's source with ast: no Blender."""

import ast
import importlib.util
import os
import string

import pytest

ADDON = os.path.join(os.path.dirname(__file__), "..", "..", "addon", "kodawari")


def _load(name, relative):
    spec = importlib.util.spec_from_file_location(name, os.path.join(ADDON, relative))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


drawn = _load("kodawari_drawn", "translations/drawn.py")
ja = _load("kodawari_ja", "translations/ja.py")


def _untranslatable(node):
    """A message Blender cannot look up: an f-string, a bare literal, or text glued to one."""
    if isinstance(node, ast.JoinedStr):
        return True
    if isinstance(node, ast.Constant) and isinstance(node.value, str):
        return True
    if isinstance(node, ast.BinOp):
        return _untranslatable(node.left) or _untranslatable(node.right)
    return False


def _messages():
    """(file:line, call, message node) for every report and BakeError in the add-on."""
    for path in drawn.sources():
        tree = drawn._parse(path)
        where = os.path.relpath(path, ADDON)
        for node in ast.walk(tree):
            if not isinstance(node, ast.Call):
                continue
            func = node.func
            if (
                isinstance(func, ast.Attribute)
                and func.attr == "report"
                and len(node.args) == 2
                and isinstance(func.value, ast.Name)
                and func.value.id == "self"
            ):
                yield f"{where}:{node.lineno}", "self.report", node.args[1]
            if isinstance(func, ast.Name) and func.id == "BakeError" and node.args:
                yield f"{where}:{node.lineno}", "BakeError", node.args[0]


def test_reports_and_bake_errors_pass_a_msgid_through_tip():
    messages = list(_messages())
    assert len(messages) > 40  # the walk really finds the add-on's reports
    bad = [f"{where} {call}" for where, call, node in messages if _untranslatable(node)]
    assert not bad, "f-string or bare text Blender cannot translate (use tip_(...).format):\n" + (
        "\n".join(bad)
    )


def test_every_report_msgid_has_japanese():
    msgids = drawn.reports()
    assert "Cannot bind '{}' to a swim axis: {}" in msgids
    missing = sorted(m for m in msgids if m not in ja.STRINGS)
    assert not missing, "reports without a Japanese entry in translations/ja.py:\n" + (
        "\n".join(missing)
    )


def _specs(text):
    return sorted(spec for _, field, spec, _ in string.Formatter().parse(text) if field is not None)


@pytest.mark.parametrize("msgid", sorted(drawn.reports()))
def test_japanese_report_keeps_every_placeholder(msgid):
    text = ja.STRINGS.get(msgid)
    if text is not None:
        # Same placeholders (the Japanese may reorder them with {0} {1}) and it formats
        # with the arguments the English takes.
        assert _specs(text) == _specs(msgid), (msgid, text)
        args = [1.5] * len(_specs(msgid))
        assert len(text.format(*args)) > 0
