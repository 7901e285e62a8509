"""The packages import one way: the layer picture in docs/architecture.md against the code;
and each name has one home (a module's ``__all__`` lists only what it defines).

Every import in ``src/pointnav_core`` (module-level, function-level and ``TYPE_CHECKING``
ones alike) is read with ``ast`` and mapped to its package; an import may go to its own
package or to one on a lower line of the picture, never sideways or up.
"""

from __future__ import annotations

import ast
import re
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
PACKAGE = ROOT / "src" / "pointnav_core"
PICTURE = ROOT / "docs" / "architecture.md"


def picture_layers(text: str) -> list[list[str]]:
    """The picture's lines, bottom first, each a list of package names."""
    after = text.split("<!-- layers: read by tests/test_layers.py -->", 1)[1]
    block = re.search(r"```text\n(.*?)```", after, re.S)
    assert block, "docs/architecture.md has no layer picture after its marker"
    lines = [line.split() for line in block.group(1).splitlines() if line.strip()]
    return lines[::-1]


def package_of(module: str) -> str:
    """``pointnav_core.floor.maps`` -> ``floor``; ``pointnav_core.errors`` -> ``errors``."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 else ""


def imports_of(path: Path) -> list[tuple[int, str]]:
    """Every ``pointnav_core`` module a file imports, with its line."""
    found = []
    for node in ast.walk(ast.parse(path.read_text())):
        if isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            if node.module == "pointnav_core":
                found += [(node.lineno, f"pointnav_core.{a.name}") for a in node.names]
            elif node.module.startswith("pointnav_core."):
                found.append((node.lineno, node.module))
        elif isinstance(node, ast.Import):
            found += [(node.lineno, a.name) for a in node.names if a.name.startswith("pointnav_core.")]
    return found


def is_kernel(module: str) -> bool:
    return bool(re.fullmatch(r"_\w*kernel", module.rsplit(".", 1)[-1]))


def violations(layers: list[list[str]]) -> list[str]:
    """The imports that break the picture, as ``file:line: a -> b`` strings."""
    level = {name: i for i, line in enumerate(layers) for name in line}
    bad = []
    for path in sorted(PACKAGE.rglob("*.py")):
        rel = path.relative_to(PACKAGE.parent).with_suffix("")
        module = ".".join(rel.parts).removesuffix(".__init__")
        if module == "pointnav_core":
            continue  # the root is the library's API: it may name any package
        source = package_of(module)
        for line, target in imports_of(path):
            dest = package_of(target)
            if dest == source or target == "pointnav_core.__version__":
                continue
            if any(part.startswith("_") for part in target.split(".")[2:]) and not (
                is_kernel(module) and is_kernel(target)
            ):
                bad.append(f"{rel}:{line}: {source} -> {target} (a private module of another package)")
            elif level.get(dest, len(layers)) >= level.get(source, -1):
                bad.append(f"{rel}:{line}: {source} -> {dest} ({target})")
    return bad


def test_every_package_is_in_the_picture_once():
    layers = picture_layers(PICTURE.read_text())
    drawn = [name for line in layers for name in line]
    packages = sorted(
        p.name for p in PACKAGE.iterdir() if (p / "__init__.py").exists()
    ) + sorted(p.stem for p in PACKAGE.glob("*.py") if p.stem != "__init__")
    assert sorted(drawn) == sorted(packages)
    assert len(drawn) == len(set(drawn))


def test_imports_follow_the_picture():
    assert violations(picture_layers(PICTURE.read_text())) == []


@pytest.mark.parametrize(
    ("picture", "expect"),
    [
        # the task above sensors: sensors' imports of task terms go up
        ("cli testing\ntraining\nevaluation\nvector policies integrations\nenvs\nrender\ntask\nsensors\n"
         "datasets backends\nscenes\ngeodesic\nfloorplans\nfloor\nutils transforms\nerrors", "sensors -> task"),
        # two packages on one line may not import each other
        ("cli testing\ntraining\nevaluation\nvector policies integrations\nenvs\nrender sensors task\n"
         "datasets backends\nscenes\ngeodesic\nfloorplans\nfloor\nutils transforms\nerrors", "sensors -> task"),
    ],
)
def test_a_wrong_picture_is_caught(picture, expect):
    text = f"<!-- layers: read by tests/test_layers.py -->\n```text\n{picture}\n```\n"
    found = violations(picture_layers(text))
    assert any(expect in v for v in found), found


def _re_exports(path: Path) -> list[str]:
    """Names a module's ``__all__`` lists that the module does not define itself."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    defined = set()
    for node in tree.body:
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            defined.add(node.name)
        elif isinstance(node, (ast.Assign, ast.AnnAssign)):
            targets = node.targets if isinstance(node, ast.Assign) else [node.target]
            defined.update(n.id for t in targets for n in ast.walk(t) if isinstance(n, ast.Name))
    listed = [
        ast.literal_eval(node.value)
        for node in tree.body
        if isinstance(node, ast.Assign) and any(getattr(t, "id", "") == "__all__" for t in node.targets)
    ]
    return sorted(set(listed[0]) - defined) if listed else []


def test_no_module_re_exports_another_modules_names():
    # A package's __init__ is its API and gathers names; any other module lists only what
    # it defines, so that each name has one home (no compatibility re-exports).
    src = ROOT / "src"
    found = {str(p.relative_to(src)): names for p in src.rglob("*.py") if p.name != "__init__.py" and (names := _re_exports(p))}
    assert found == {}


def test_a_re_export_is_caught(tmp_path):
    module = tmp_path / "m.py"
    module.write_text("from os import sep\nX = 1\n\ndef f():\n    pass\n\n__all__ = ['X', 'f', 'sep']\n")
    assert _re_exports(module) == ["sep"]
