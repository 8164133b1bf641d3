"""Every feature folder has the same files in the same roles (CONTRIBUTING.md, "Adding a
feature"), and no feature imports itself round in a circle. Read from the source with
ast, so this runs without Blender."""

import ast
from pathlib import Path

import pytest

ADDON = Path(__file__).resolve().parents[2] / "addon" / "kodawari"
FEATURES = ("fish", "hair", "gait")
ROLE_FILES = ("__init__.py", "props.py", "ops.py", "panel.py", "runtime.py", "handlers.py")


def _tree(path):
    return ast.parse(path.read_text(encoding="utf-8"), filename=str(path))


def _sibling_imports(path):
    """Modules of the same package that `path` imports, at the top or inside functions."""
    found = set()
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.ImportFrom) and node.level == 1:
            if node.module:
                found.add(node.module.split(".")[0])
            else:
                found.update(alias.name for alias in node.names)
    return found


def _persistent_functions(path):
    names = []
    for node in ast.walk(_tree(path)):
        if isinstance(node, ast.FunctionDef):
            for decorator in node.decorator_list:
                target = (
                    decorator.attr
                    if isinstance(decorator, ast.Attribute)
                    else getattr(decorator, "id", "")
                )
                if target == "persistent":
                    names.append(node.name)
    return names


@pytest.mark.parametrize("feature", FEATURES)
def test_every_feature_has_the_same_role_files(feature):
    folder = ADDON / feature
    missing = [name for name in ROLE_FILES if not (folder / name).is_file()]
    assert not missing, f"{feature}/ lacks {missing}"


@pytest.mark.parametrize("feature", FEATURES)
def test_the_package_init_lists_classes_properties_and_handlers(feature):
    tree = _tree(ADDON / feature / "__init__.py")
    assigned = {
        target.id
        for node in tree.body
        if isinstance(node, ast.Assign)
        for target in node.targets
        if isinstance(target, ast.Name)
    }
    assert {"CLASSES", "PROPERTIES", "HANDLERS"} <= assigned


@pytest.mark.parametrize("feature", FEATURES)
def test_application_handlers_live_only_in_handlers_py(feature):
    elsewhere = {
        path.name: _persistent_functions(path)
        for path in sorted((ADDON / feature).glob("*.py"))
        if path.name != "handlers.py" and _persistent_functions(path)
    }
    assert not elsewhere, f"@persistent handlers outside {feature}/handlers.py: {elsewhere}"
    assert _persistent_functions(ADDON / feature / "handlers.py")


@pytest.mark.parametrize("feature", FEATURES)
def test_no_import_circle_inside_a_feature(feature):
    folder = ADDON / feature
    modules = {path.stem for path in folder.glob("*.py") if path.stem != "__init__"}
    graph = {name: _sibling_imports(folder / f"{name}.py") & modules for name in modules}

    def cycle_from(start):
        stack = [(start, [start])]
        while stack:
            node, trail = stack.pop()
            for nxt in sorted(graph[node]):
                if nxt == start:
                    return [*trail, start]
                if nxt not in trail:
                    stack.append((nxt, [*trail, nxt]))
        return None

    cycles = [c for c in (cycle_from(name) for name in sorted(modules)) if c]
    assert not cycles, f"{feature}/ imports in a circle: {' -> '.join(cycles[0])}"
