"""Every node's parameter table is declared one way: settings dataclasses read by ``specs_of``,
one-line descriptions (the rest is docs/parameters.md's), and nodes that build their objects
before their parameter callbacks validate, with no ``hasattr``/``getattr`` on themselves."""

from __future__ import annotations

import ast
import importlib.util
from pathlib import Path
from typing import Any

import pytest

from haptic_dob.nodes.registry import NODES
from support.paths import ROOT

LONGEST = 80  # characters of a description: one line of ``ros2 param describe``


def node_tables() -> list[tuple[str, str, list[Any]]]:
    """(node, ros2 run name, rows) as docs/parameters.md lists them (``scripts/param_docs.py``)."""
    spec = importlib.util.spec_from_file_location("param_docs", ROOT / "scripts" / "param_docs.py")
    assert spec is not None and spec.loader is not None
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    tables: list[tuple[str, str, list[Any]]] = module.tables()
    return tables


TABLES = node_tables()


def test_every_registered_node_has_its_table_documented() -> None:
    assert sorted(node for node, _, _ in TABLES) == sorted(NODES)


@pytest.mark.parametrize(
    ("node", "rows"), [(n, r) for n, _, r in TABLES], ids=[n for n, _, _ in TABLES]
)
def test_every_description_is_one_short_line(node: str, rows: list[Any]) -> None:
    for row in rows:
        text = row.description
        assert text and "\n" not in text and len(text) <= LONGEST, (node, row.name, len(text))
        assert "\n" not in row.full_description(), (node, row.name)


def python_files(*parts: str) -> list[Path]:
    return sorted(p for part in parts for p in (ROOT / part).rglob("*.py"))


def calls(path: Path) -> list[ast.Call]:
    tree = ast.parse(path.read_text(encoding="utf-8"))
    return [n for n in ast.walk(tree) if isinstance(n, ast.Call)]


def test_only_the_parameters_module_makes_rows() -> None:
    made = [
        f"{p.relative_to(ROOT)}:{c.lineno}"
        for p in python_files("src", "scripts")
        if p.name != "params.py" or p.parent.name != "runtime"
        for c in calls(p)
        if isinstance(c.func, ast.Name) and c.func.id == "ParamSpec"
    ]
    assert made == [], "rows come from settings dataclasses through specs_of"


def test_no_node_asks_whether_its_own_attributes_exist_yet() -> None:
    asked = [
        f"{p.relative_to(ROOT)}:{c.lineno}"
        for p in python_files(
            "src/haptic_dob/nodes", "src/haptic_sim/nodes", "src/haptic_dob/runtime/ros"
        )
        for c in calls(p)
        if isinstance(c.func, ast.Name)
        and c.func.id in ("getattr", "hasattr")
        and c.args
        and isinstance(c.args[0], ast.Name)
        and c.args[0].id == "self"
    ]
    assert asked == []
