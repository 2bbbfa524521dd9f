"""Docstrings state contracts in 15 lines or fewer; reasons and history live in docs and git."""

from __future__ import annotations

import ast
from pathlib import Path

from support.paths import ROOT

MAX_LINES = 15
TREES = ("src", "scripts", "test")
Documented = ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef


def long_docstrings(path: Path, base: Path, limit: int = MAX_LINES) -> list[str]:
    """``file:line name (N lines)`` (file relative to ``base``) for every docstring in ``path``
    over ``limit`` lines."""
    found = []
    for node in ast.walk(ast.parse(path.read_text(), filename=str(path))):
        if not isinstance(node, Documented):
            continue
        doc = ast.get_docstring(node, clean=False)
        if doc is None:
            continue
        lines = doc.count("\n") + 1
        if lines > limit:
            line = node.body[0].lineno
            name = getattr(node, "name", "<module>")
            found.append(f"{path.relative_to(base)}:{line} {name} ({lines} lines)")
    return found


def test_a_long_docstring_is_found(tmp_path: Path) -> None:
    body = "\n".join(f"line {i}" for i in range(MAX_LINES + 1))
    planted = tmp_path / "probe.py"
    planted.write_text(f'"""{body}"""\n\n\ndef f() -> None:\n    """One line."""\n')
    assert long_docstrings(planted, tmp_path) == ["probe.py:1 <module> (16 lines)"]


def test_no_docstring_is_over_15_lines() -> None:
    files = sorted(p for tree in TREES for p in (ROOT / tree).rglob("*.py"))
    assert len(files) > 100
    found = [hit for path in files for hit in long_docstrings(path, ROOT)]
    assert not found, "docstrings over 15 lines:\n" + "\n".join(found)
