"""Sizes stay readable: no module under ``src/`` over 500 lines, no function over 80.

A function's length is its whole ``def`` (signature, docstring and body:
``end_lineno - lineno + 1``); a module's is its line count.
"""

import ast
from pathlib import Path

SRC = Path(__file__).resolve().parents[1] / "src"
MAX_MODULE_LINES = 500
MAX_FUNCTION_LINES = 80


def _modules() -> list[Path]:
    return sorted(SRC.rglob("*.py"))


def _long_functions(path: Path) -> list[tuple[str, int]]:
    """``(name, lines)`` of every function in ``path`` longer than the limit."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [
        (node.name, node.end_lineno - node.lineno + 1)
        for node in ast.walk(tree)
        if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef))
        and node.end_lineno - node.lineno + 1 > MAX_FUNCTION_LINES
    ]


def test_the_source_is_found():
    assert len(_modules()) > 100


def test_no_module_is_over_500_lines():
    long = {}
    for path in _modules():
        n = len(path.read_text(encoding="utf-8").splitlines())
        if n > MAX_MODULE_LINES:
            long[str(path.relative_to(SRC))] = n
    assert not long, long


def test_no_function_is_over_80_lines():
    long = {}
    for path in _modules():
        for name, n in _long_functions(path):
            long[f"{path.relative_to(SRC).as_posix()}:{name}"] = n
    assert not long, long


def test_the_check_catches_a_long_function(tmp_path):
    bad = tmp_path / "long.py"
    bad.write_text("def f():\n" + "    x = 1\n" * MAX_FUNCTION_LINES)
    assert _long_functions(bad) == [("f", MAX_FUNCTION_LINES + 1)]
