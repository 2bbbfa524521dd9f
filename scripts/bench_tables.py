"""BENCHMARKS.md's tables, measured on the machine at hand: ``make bench``.

    .venv/bin/python scripts/bench_tables.py                      # every row, BENCHMARKS.md
    .venv/bin/python scripts/bench_tables.py --only margin lockstep --note "shared machine"
    .venv/bin/python scripts/bench_tables.py --print              # print, do not rewrite

A table that ``make bench`` fills follows a line ``<!-- bench:AREA -->`` and has the columns
What, Figure, Command, Machine, Date. ``ROWS`` holds each area's rows: a benchmark of
``benchmarks.py``, ``bench_models.py`` or ``bench_analysis.py`` with its arguments, so a row's
Command measures that row alone. After each row the file is rewritten: the row whose Command is
the one measured is replaced (or appended to its area's table); every other row (measured by
hand, or on another machine) stays as it is. The Machine cell names the CPU, its cores, Python,
the load average when the row started and ``--note``; the Date cell the day and the commit.
"""

from __future__ import annotations

import argparse
import os
import re
import subprocess
import sys
import time
from dataclasses import dataclass
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_analysis
import bench_models
import benchmarks

ROOT = Path(__file__).resolve().parents[1]
HEADER = ("What", "Figure", "Command", "Machine", "Date")
MARKER = re.compile(r"^<!-- bench:([a-z-]+) -->$")
DOB = ("--set", "controller_node:mode=DOB", "--set", "controller_node:kf=1.0")


@dataclass(frozen=True)
class TableRow:
    """One row ``make bench`` measures: its area, what it is, the script and its arguments."""

    area: str
    what: str
    script: str  # benchmarks.py, bench_models.py or bench_analysis.py
    args: tuple[str, ...]

    @property
    def name(self) -> str:
        """The benchmark's name (``--only`` picks rows by it): its first argument, or the bag."""
        return self.args[1] if self.script == "bench_analysis.py" else self.args[0]

    @property
    def command(self) -> str:
        """The Command cell: what measures this row alone."""
        return f"`.venv/bin/python scripts/{self.script} {' '.join(self.args)}`"

    def measure(self) -> str:
        """Run the benchmark; its one-line result."""
        if self.script == "bench_analysis.py":
            storage = self.args[3] if len(self.args) > 3 else "mcap"
            return bench_analysis.bench_bag(self.args[1], storage)
        repeat = int(self.args[self.args.index("--repeat") + 1])
        if self.script == "bench_models.py":
            return bench_models.BENCHMARKS[self.name](repeat)
        a = benchmarks.parser().parse_args(list(self.args))  # every option, as the Command's
        benchmarks.apply(a)
        return benchmarks.BENCHMARKS[self.name](a.repeat)


def _row(area: str, what: str, script: str, *args: str) -> TableRow:
    return TableRow(area, what, script, args)


ROWS = [
    _row("core", "40 s slide session in batch (default config), OL and DOB Kf = 1: real-time "
         "factor and one cycle (the batch cycle)", "benchmarks.py", "batch", "--repeat", "5"),
    _row("core", "one slide observer update (checks, implicit update, clip)",
         "benchmarks.py", "observer", "--repeat", "5"),
    _row("core", "the bridge's velocity from a position-only state, a Touch's three joints' "
         "counts at 500 Hz: the adaptive window and the Kalman filter, per state",
         "benchmarks.py", "velocity", "--repeat", "5"),
    _row("models", "one PHANToM 1.5 observer update (pinocchio), and update + wrench",
         "bench_models.py", "phantom", "--repeat", "9"),
    _row("models", "one 7-DOF URDF arm observer update (`config/urdf/arm7.urdf`)",
         "bench_models.py", "arm7", "--repeat", "9"),
    _row("models", "one 1 kHz cycle of the simulated PHANToM (10 RK4 sub-steps), without and "
         "with the semi-random hand", "bench_models.py", "phantom_sim", "--repeat", "7"),
    _row("floors", "one raw DDS hop between two processes (ping-pong of a small raw message, "
         "events executors, the loop's QoS)", "benchmarks.py", "hop", "--repeat", "3"),
    _row("floors", "message patterns between processes that only pass messages, interleaved "
         "round by round: the loop's (4 processes), one message taken by two (4), a ring of "
         "three, a ping-pong; cycle and its ratio to as many hops as it passes in sequence",
         "benchmarks.py", "pattern", "--repeat", "3"),
    _row("floors", "this machine's own stalls: an idle loop per CPU waking every 1 ms for 20 s",
         "benchmarks.py", "timer-floor", "--repeat", "3"),
    _row("floors", "the on-time floor: a driver-like process's state at each 1 kHz instant, "
         "answered by a process that works before and after its answer (pure Python, as long "
         "as given), 10 s, both under SCHED_FIFO 50 and PM QoS 0: answers before the next "
         "instant", "benchmarks.py", "answer-floor", "--repeat", "5", "--rt-priority", "50",
         "--cpu-latency", "0"),
    _row("lockstep", "default layout (the loop's four nodes in one process, `haptic-launch "
         "slide_sim`), DOB Kf = 1, 20 s simulated", "benchmarks.py", "lockstep", "--repeat",
         "3", *DOB),
    _row("lockstep", "every node in one process (`--composed`), DOB Kf = 1",
         "benchmarks.py", "lockstep-composed", "--repeat", "3", *DOB),
    _row("lockstep", "a process per node (`--processes`), DOB Kf = 1",
         "benchmarks.py", "lockstep-processes", "--repeat", "3", *DOB),
    _row("lockstep", "the loop against its floors, DOB Kf = 1, each ratio within one run: "
         "composed / batch cycle; 4 processes / (3 raw hops + batch cycle); 4 processes / (the "
         "loop's message pattern + batch cycle)", "benchmarks.py", "margin", "--repeat", "3"),
    _row("realtime", "default layout, DOB Kf = 1, 1 kHz, 20 s", "benchmarks.py", "realtime",
         "--repeat", "3", *DOB),
    _row("realtime", "every node in one process (`--composed`), DOB Kf = 1",
         "benchmarks.py", "realtime-composed", "--repeat", "3", *DOB),
    _row("realtime", "a process per node (`--processes`), DOB Kf = 1",
         "benchmarks.py", "realtime-processes", "--repeat", "3", *DOB),
    _row("realtime", "a process per node, OL, 3 s, as `test_graph_realtime` runs it: median "
         "latency against three raw hops (the slower of before and after)",
         "benchmarks.py", "realtime-margin", "--repeat", "3"),
    _row("bridge", "the bridge composed with the loop against a test driver (Force Dimension-"
         "like at 1 kHz, Touch-like at 500 Hz, a Franka-like arm at 1 kHz as a teleoperation "
         "slave), 10 s: driver state -> command latency against one raw hop, commands before "
         "the driver's next state", "benchmarks.py", "bridge", "--repeat", "3"),
    _row("bridge", "the same, the loop and the driver under SCHED_FIFO 50 (`--rt-priority 50`; "
         "the driver under SCHED_FIFO 50 too, as a controller manager runs)", "benchmarks.py",
         "bridge", "--repeat", "3", "--rt-priority", "50"),
    _row("bridge", "the same under SCHED_FIFO 50, the driver and the loop on CPU 1 alone "
         "(`--cpus 1`: the CPU this machine stalls least, below)", "benchmarks.py",
         "bridge", "--repeat", "3", "--rt-priority", "50", "--cpus", "1"),
    _row("logging", "one log call in a node's process (the device's modules loaded): rclpy's "
         "logger and `LoopLog`, first call, said, throttled away", "benchmarks.py", "log",
         "--repeat", "3"),
    _row("analysis", "`haptic-analyze` of a 40 s, 1 kHz bag (every session topic), MCAP, "
         "process start to output", "bench_analysis.py", "--only", "40s"),
    _row("analysis", "the same bag in sqlite3", "bench_analysis.py", "--only", "40s",
         "--storage", "sqlite3"),
]  # fmt: skip


def _cells(line: str) -> list[str]:
    """The cells of a markdown table line (``\\|`` is a pipe within a cell)."""
    inner = line.strip()[1:-1]
    return [c.strip() for c in re.split(r"(?<!\\)\|", inner)]


def _line(cells: list[str] | tuple[str, ...]) -> str:
    return "| " + " | ".join(cells) + " |"


def rewrite(text: str, area: str, cells: list[str]) -> str:
    """``text`` with the row ``cells`` in the table of ``area``: in place of the row of the same
    Command, else appended. Raises ``ValueError`` when the area has no marked table."""
    lines = text.split("\n")
    for i, line in enumerate(lines):
        found = MARKER.match(line)
        if found is None or found.group(1) != area:
            continue
        end = i + 1
        while end < len(lines) and lines[end].startswith("|"):
            end += 1
        rows = [_cells(x) for x in lines[i + 3 : end]]
        same = [j for j, r in enumerate(rows) if len(r) > 2 and r[2] == cells[2]]
        if same:
            rows[same[0]] = cells
        else:
            rows.append(cells)
        table = [_line(HEADER), _line(["---"] * len(HEADER)), *map(_line, rows)]
        return "\n".join([*lines[: i + 1], *table, *lines[end:]])
    raise ValueError(f"no table marked <!-- bench:{area} -->")


def _commit() -> str:
    """The short commit measured, ``+`` when the tree (but for BENCHMARKS.md) has changes."""
    try:
        head = subprocess.run(
            ["git", "rev-parse", "--short", "HEAD"], cwd=ROOT, capture_output=True, text=True
        ).stdout.strip()
        dirty = subprocess.run(
            ["git", "status", "--porcelain", "--", ".", ":!BENCHMARKS.md"],
            cwd=ROOT,
            capture_output=True,
            text=True,
        ).stdout.strip()
    except OSError:
        return ""
    return head + "+" * bool(dirty)


def main(argv: list[str] | None = None) -> int:
    """Measure the rows (all, or ``--only`` those benchmarks) and rewrite or print them."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("file", nargs="?", default=str(ROOT / "BENCHMARKS.md"), help="the tables")
    p.add_argument("--only", nargs="+", metavar="NAME", help="only these benchmarks' rows")
    p.add_argument("--note", default="", help="added to each row's Machine cell")
    p.add_argument("--print", action="store_true", help="print the rows, do not rewrite")
    a = p.parse_args(argv)
    rows = [r for r in ROWS if a.only is None or r.name in a.only]
    unknown = set(a.only or ()) - {r.name for r in rows}
    if unknown:
        p.error(f"no row measures {', '.join(sorted(unknown))}")
    path = Path(a.file)
    commit = _commit()
    for row in rows:
        load = os.getloadavg()[0]
        t0 = time.monotonic()
        try:
            figure = row.measure()
        except (RuntimeError, ValueError) as exc:  # a launch that failed, a refused request
            print(f"ERROR: {row.name}: {' '.join(str(exc).split())}", file=sys.stderr)
            return 1
        note = f"; {a.note}" if a.note else ""
        cells = [
            row.what,
            figure.replace("|", "\\|"),
            row.command,
            f"{benchmarks.machine()}; load {load:.1f} at the start{note}",
            f"{time.strftime('%Y-%m-%d')} ({commit})" if commit else time.strftime("%Y-%m-%d"),
        ]
        print(f"{row.area}: {_line(cells)}  [{time.monotonic() - t0:.0f} s]", flush=True)
        if not a.print:
            path.write_text(rewrite(path.read_text(), row.area, cells))
    return 0


if __name__ == "__main__":
    sys.exit(main())
