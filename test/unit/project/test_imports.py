"""Imports sit at a module's top; one inside a function says why with a ``# lazy:`` comment.

A function-level import hides a module's dependencies and, unmarked, reads as an accident. The
few that are meant (a heavy library kept off a start-up path, rclpy kept out of ROS-free code, a
cycle) carry ``# lazy: <reason>`` on their line or the line before; a run of imports with no other
statement between them (blank lines and comments may separate their groups) shares the mark of
its first one.
"""

from __future__ import annotations

import ast
import pathlib

import pytest

from support.paths import ROOT

MARK = "# lazy:"
IMPORT = (ast.Import, ast.ImportFrom)
FUNCTION = (ast.FunctionDef, ast.AsyncFunctionDef)


def marked(lines: list[str], node: ast.stmt) -> bool:
    """Whether ``node``'s lines, or the line before it, carry the mark (lines numbered from 1)."""
    end = node.end_lineno or node.lineno
    return any(MARK in lines[i - 1] for i in range(max(1, node.lineno - 1), end + 1))


def unmarked_imports(path: pathlib.Path) -> list[str]:
    """``file:line`` of every import inside a function body of ``path`` with no ``# lazy:``."""
    source = path.read_text(encoding="utf-8")
    lines = source.splitlines()
    found: list[str] = []

    def visit_body(body: list[ast.stmt], in_function: bool) -> None:
        run_marked = False  # the mark of the run of imports the previous statement is in
        for stmt in body:
            if isinstance(stmt, IMPORT):
                run_marked = run_marked or marked(lines, stmt)
                if in_function and not run_marked:
                    found.append(f"{path}:{stmt.lineno}")
            else:
                run_marked = False
                visit(stmt, in_function)

    def visit(node: ast.AST, in_function: bool) -> None:
        inside = in_function or isinstance(node, FUNCTION)
        for field in ("body", "orelse", "finalbody"):
            block = getattr(node, field, None)
            if isinstance(block, list) and block and isinstance(block[0], ast.stmt):
                visit_body(block, inside)
        for handler in getattr(node, "handlers", ()):
            visit_body(handler.body, inside)
        for case in getattr(node, "cases", ()):
            visit_body(case.body, inside)

    visit(ast.parse(source, filename=str(path)), in_function=False)
    return found


def sources() -> list[pathlib.Path]:
    """Every Python file of the packages and the scripts."""
    return sorted([*(ROOT / "src").rglob("*.py"), *(ROOT / "scripts").rglob("*.py")])


def test_there_are_sources() -> None:
    names = {p.relative_to(ROOT).as_posix() for p in sources()}
    assert "src/haptic_dob/core/cycle.py" in names and "scripts/benchmarks.py" in names


def test_every_import_in_a_function_says_why() -> None:
    found = [hit for path in sources() for hit in unmarked_imports(path)]
    bad = [str(pathlib.Path(hit).relative_to(ROOT)) for hit in found]
    assert bad == [], "import inside a function without '# lazy: <reason>':\n" + "\n".join(bad)


PLANTED = """\
import os


def at_top() -> str:
    return os.sep


def hidden() -> object:
    import json
    return json


def said(flag: bool) -> object:
    import json  # lazy: a reason
    if flag:
        # lazy: another reason
        import csv

        import pickle

        flag = not flag
        import shelve
        return csv, pickle, shelve
    return json


class Holder:
    def method(self) -> object:
        try:
            from collections import OrderedDict
        except ImportError:
            return None
        return OrderedDict
"""


@pytest.mark.parametrize("where", ["function", "method in try"])
def test_the_check_finds_a_planted_import(tmp_path: pathlib.Path, where: str) -> None:
    path = tmp_path / "planted.py"
    path.write_text(PLANTED, encoding="utf-8")
    found = unmarked_imports(path)
    line = {"function": 9, "method in try": 30}[where]
    assert f"{path}:{line}" in found


def test_the_check_passes_marked_imports_and_runs_but_not_past_a_statement(
    tmp_path: pathlib.Path,
) -> None:
    path = tmp_path / "planted.py"
    path.write_text(PLANTED, encoding="utf-8")
    assert unmarked_imports(path) == [f"{path}:9", f"{path}:22", f"{path}:30"]
