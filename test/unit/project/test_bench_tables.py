"""``make bench`` rewrites BENCHMARKS.md's marked tables in place: every row it measures has a
marked table, a measured row replaces the row of the same command, other rows stay."""

from __future__ import annotations

import importlib
import sys
from types import ModuleType

import pytest

from support.paths import ROOT


@pytest.fixture(scope="module")
def tables() -> ModuleType:
    sys.path.insert(0, str(ROOT / "scripts"))
    try:
        return importlib.import_module("bench_tables")
    finally:
        sys.path.remove(str(ROOT / "scripts"))


def test_every_measured_row_has_its_table_and_a_command_of_its_own(tables: ModuleType) -> None:
    text = (ROOT / "BENCHMARKS.md").read_text()
    header = "| " + " | ".join(tables.HEADER) + " |"
    for area in {r.area for r in tables.ROWS}:
        marker = f"<!-- bench:{area} -->"
        assert f"{marker}\n{header}\n" in text, area
    commands = [r.command for r in tables.ROWS]
    assert len(set(commands)) == len(commands)


def test_a_row_is_replaced_by_its_command_and_the_others_stay(tables: ModuleType) -> None:
    text = "\n".join(
        [
            "## Area",
            "<!-- bench:core -->",
            "| What | Figure | Command | Machine | Date |",
            "|---|---|---|---|---|",
            "| by hand | 1 \\| 2 | `make x` | A | 2026-01-01 |",
            "| measured | old | `cmd a` | A | 2026-01-01 |",
            "",
            "<!-- bench:other -->",
            "| What | Figure | Command | Machine | Date |",
            "|---|---|---|---|---|",
            "text after",
        ]
    )
    new = ["measured", "new", "`cmd a`", "B", "2026-02-02"]
    got = tables.rewrite(text, "core", new).split("\n")
    assert got[4:6] == [
        "| by hand | 1 \\| 2 | `make x` | A | 2026-01-01 |",
        "| measured | new | `cmd a` | B | 2026-02-02 |",
    ]
    appended = tables.rewrite(text, "other", ["b", "c", "`cmd b`", "B", "d"]).split("\n")
    assert appended[-2:] == ["| b | c | `cmd b` | B | d |", "text after"]
    with pytest.raises(ValueError, match="no table marked <!-- bench:missing -->"):
        tables.rewrite(text, "missing", new)


def test_a_row_measures_with_every_option_of_its_command(
    tables: ModuleType, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The Command cell is what ran: ``--rt-priority``, ``--cpus`` and ``--set`` reach the
    benchmark (they once went missing, and a SCHED_FIFO row measured default scheduling)."""
    import bench_bridge
    import bench_graph

    seen: list[tuple[list[str], list[str], int]] = []

    def fake(repeat: int) -> str:
        seen.append((list(bench_graph.GRAPH_ARGS), list(bench_bridge.CPUS), repeat))
        return "figures"

    monkeypatch.setitem(tables.benchmarks.BENCHMARKS, "bridge", fake)
    row = tables.TableRow(
        "bridge",
        "w",
        "benchmarks.py",
        ("bridge", "--repeat", "2", "--rt-priority", "50", "--cpus", "1", "--set", "a:b=1"),
    )
    assert row.measure() == "figures"
    assert seen == [(["--set", "a:b=1", "--rt-priority", "50"], ["1"], 2)]
    plain = tables.TableRow("bridge", "w", "benchmarks.py", ("bridge", "--repeat", "1"))
    plain.measure()
    assert seen[-1] == ([], [], 1)
