"""Benchmarks of the suite (not timed tests): each prints medians over repeated runs.

Usage: ``.venv/bin/python scripts/benchmarks.py [NAME ...] [--repeat N]``; without names, all
run, one line each. ``make bench`` (``bench_tables.py``) runs them as BENCHMARKS.md's rows give
them and rewrites those rows with the figures, the machine and the date.
"""

from __future__ import annotations

import argparse
import os
import platform
import sys
from collections.abc import Callable
from pathlib import Path

# the benchmarks live beside this script by what they measure: bench_batch (the maths, in
# process), bench_hop and bench_pattern (DDS floors), bench_graph (the launched node graph),
# bench_timer_floor (the machine's own stalls), bench_answer_floor (the on-time share any loop
# of a given cost gets), bench_margin (the graph against its floors)
sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_answer_floor import bench_answer_floor
from bench_batch import bench_batch_session, bench_observer_update, bench_velocity
from bench_bridge import CPUS, ONLY, PROFILES, bench_bridge
from bench_graph import (
    GRAPH_ARGS,
    bench_lockstep,
    bench_lockstep_composed,
    bench_lockstep_processes,
    bench_realtime,
    bench_realtime_composed,
    bench_realtime_processes,
)
from bench_hop import bench_hop
from bench_log import bench_log
from bench_margin import bench_margin, bench_realtime_margin
from bench_pattern import bench_pattern
from bench_timer_floor import bench_timer_floor
from haptic_dob.runtime.cpus import checked_cpus


def machine() -> str:
    """CPU model, core count and Python version of this machine."""
    model = platform.processor() or "unknown CPU"
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as fh:
            for line in fh:
                if line.startswith("model name"):
                    model = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    return f"{model}, {os.cpu_count()} cores, Python {platform.python_version()}"


BENCHMARKS: dict[str, Callable[[int], str]] = {
    "batch": bench_batch_session,
    "observer": bench_observer_update,
    "velocity": bench_velocity,
    "lockstep": bench_lockstep,
    "lockstep-composed": bench_lockstep_composed,
    "lockstep-processes": bench_lockstep_processes,
    "realtime": bench_realtime,
    "realtime-composed": bench_realtime_composed,
    "realtime-processes": bench_realtime_processes,
    "timer-floor": bench_timer_floor,
    "answer-floor": bench_answer_floor,
    "hop": bench_hop,
    "pattern": bench_pattern,
    "margin": bench_margin,
    "realtime-margin": bench_realtime_margin,
    "log": bench_log,
    "bridge": bench_bridge,
}


def parser() -> argparse.ArgumentParser:
    """The command line: benchmark names, ``--repeat`` and the options of the graph ones."""
    p = argparse.ArgumentParser(description=__doc__)
    p.add_argument("names", nargs="*", help=f"benchmarks to run: {', '.join(BENCHMARKS)}")
    p.add_argument("--repeat", type=int, default=5, help="repetitions (median reported)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="NODE:PARAM=VALUE",
        help="a parameter of the graph benchmarks, as haptic-launch --set takes it (repeatable)",
    )
    p.add_argument(
        "--rt-priority",
        type=int,
        metavar="P",
        help="run the graph benchmarks' nodes under SCHED_FIFO priority P (haptic-launch option)",
    )
    p.add_argument(
        "--pin",
        action="store_true",
        help="pin the graph benchmarks' node processes to CPUs (haptic-launch option)",
    )
    p.add_argument(
        "--cpu-latency",
        type=int,
        metavar="US",
        help="hold a CPU wake-up latency request of US microseconds while the graph benchmarks "
        "and the floors run (haptic-launch option; PM QoS, needs root)",
    )
    p.add_argument(
        "--cpus",
        metavar="LIST",
        help="run the bridge benchmark's driver and loop under taskset -c LIST (CPU numbers, "
        "comma-separated, e.g. 1)",
    )
    p.add_argument(
        "--profiles",
        metavar="LIST",
        help="run only these of the bridge benchmark's profiles (comma-separated: "
        + ", ".join(PROFILES)
        + ")",
    )
    return p


def apply(a: argparse.Namespace) -> None:
    """Set the graph benchmarks' ``GRAPH_ARGS`` and the bridge's ``CPUS`` from ``a``."""
    CPUS[:] = [a.cpus] if a.cpus else []
    ONLY[:] = a.profiles.split(",") if a.profiles else []
    GRAPH_ARGS[:] = [x for item in a.set for x in ("--set", item)]
    if a.rt_priority is not None:
        GRAPH_ARGS.extend(["--rt-priority", str(a.rt_priority)])
    if a.pin:
        GRAPH_ARGS.append("--pin")
    if a.cpu_latency is not None:
        GRAPH_ARGS.extend(["--cpu-latency", str(a.cpu_latency)])


def main(argv: list[str] | None = None) -> int:
    """Run the named benchmarks (default: all) and print one line each."""
    p = parser()
    a = p.parse_args(argv)
    if a.cpus:
        try:
            numbers = [int(c) for c in a.cpus.split(",")]
        except ValueError:
            p.error(f"--cpus {a.cpus}: not a comma-separated list of CPU numbers")
        try:
            a.cpus = ",".join(map(str, checked_cpus(numbers)))
        except ValueError as exc:  # a CPU this process may not use
            p.error(f"--cpus {a.cpus}: {str(exc).removeprefix('cpu_affinity: ')}")
    if a.profiles and any(x not in PROFILES for x in a.profiles.split(",")):
        p.error(f"--profiles {a.profiles}: profiles are {', '.join(PROFILES)}")
    apply(a)
    unknown = [n for n in a.names if n not in BENCHMARKS]
    if unknown:
        p.error(f"unknown benchmark(s) {', '.join(unknown)}; choose from {', '.join(BENCHMARKS)}")
    print(f"machine: {machine()}")
    for name in a.names or list(BENCHMARKS):
        try:
            print(f"{name}: {BENCHMARKS[name](a.repeat)}", flush=True)
        except (RuntimeError, ValueError) as exc:  # a launch that failed, a refused request
            print(f"ERROR: {name}: {' '.join(str(exc).split())}", file=sys.stderr)
            return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
