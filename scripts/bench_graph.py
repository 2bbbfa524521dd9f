"""Benchmarks of the node graph as ``haptic-launch slide_sim`` starts it: lockstep and real time.

Each run is a fresh ``haptic-launch`` on a random ``ROS_DOMAIN_ID`` (localhost only), 20 s at
1 kHz, laid out by default (the loop's four nodes in one process), ``--composed`` or
``--processes``; ``GRAPH_ARGS`` adds the command line's ``--set``, ``--rt-priority``, ``--pin``
and ``--cpu-latency``. Each run's cycle (lockstep) or median latency (real time) is also given
against the batch cycle and one raw hop measured just before and after it (``bench_floors``).
"""

from __future__ import annotations

import json
import os
import random
import re
import statistics
import subprocess
import sys
import tempfile

from bench_floors import around, summary

#: extra ``haptic-launch`` arguments of the graph benchmarks (--set, --rt-priority, --pin,
#: --cpu-latency); ``benchmarks.py`` fills it from its command line
GRAPH_ARGS: list[str] = []


def graph_option(name: str) -> int | None:
    """The value of a ``GRAPH_ARGS`` option given as ``NAME VALUE`` (None when absent)."""
    return int(GRAPH_ARGS[GRAPH_ARGS.index(name) + 1]) if name in GRAPH_ARGS else None


def graph_sched() -> tuple[int | None, int | None]:
    """The scheduling the graph benchmarks are given (``--rt-priority``, ``--cpu-latency``)."""
    return graph_option("--rt-priority"), graph_option("--cpu-latency")


def graph_args(extra: list[str]) -> list[str]:
    """A benchmark's arguments and ``GRAPH_ARGS``; ``--pin`` only where every node has a process
    of its own (``--processes``): haptic-launch refuses it for nodes sharing a process."""
    args = [*extra, *GRAPH_ARGS]
    return args if "--processes" in args else [a for a in args if a != "--pin"]


def launch_graph(extra: list[str], sets: list[str], timeout: float) -> str:
    """Run ``haptic-launch slide_sim`` on a fresh domain; return its combined output."""
    env = dict(
        os.environ,
        ROS_DOMAIN_ID=str(random.randint(1, 100)),
        ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
    )
    argv = [os.path.join(os.path.dirname(sys.executable), "haptic-launch"), "slide_sim", *extra]
    for item in sets:
        argv += ["--set", item]
    out = subprocess.run(argv, env=env, capture_output=True, text=True, timeout=timeout)
    if out.returncode != 0:
        raise RuntimeError(f"haptic-launch failed ({out.returncode}): {out.stderr[-2000:]}")
    return out.stdout + out.stderr


def real_time_factor(extra: list[str], seconds: float = 20.0) -> float:
    """One lockstep graph run's real-time factor, as the device node reports it."""
    text = launch_graph(graph_args(extra), [f"device_node:duration_s={seconds}"], 300)
    found = re.search(r"real-time factor ([0-9.]+)", text)
    if found is None:
        raise RuntimeError(f"no real-time factor in the launch output: {text[-1500:]}")
    return float(found.group(1))


def lockstep_cycle_us(extra: list[str], seconds: float = 20.0) -> float:
    """One lockstep graph run's time per cycle (µs), from the device's real-time factor."""
    return 1e3 / real_time_factor(extra, seconds)


def _lockstep(repeat: int, extra: list[str]) -> str:
    runs = [around(lambda: real_time_factor(extra), GRAPH_ARGS) for _ in range(repeat)]
    rtf = [r for r, _ in runs]
    batch = statistics.median(1e3 / r / f.batch_us for r, f in runs)
    hop = statistics.median(1e3 / r / f.hop_us for r, f in runs)
    return (
        f"real-time factor median {statistics.median(rtf):.2f} (runs: "
        f"{', '.join(f'{r:.2f}' for r in rtf)}) -> {1e3 / statistics.median(rtf):.0f} us a "
        f"cycle, {batch:.2f}x the batch cycle, {hop:.2f}x one hop (medians of the runs' ratios; "
        f"{summary([f for _, f in runs])})"
    )


def bench_lockstep(repeat: int) -> str:
    """The lockstep graph at 1 kHz, 20 s simulated, as haptic-launch lays it out by default
    (the loop's four nodes in one process): real-time factor."""
    return _lockstep(repeat, [])


def bench_lockstep_composed(repeat: int) -> str:
    """The same graph, every node in one process (``--composed``)."""
    return _lockstep(repeat, ["--composed"])


def bench_lockstep_processes(repeat: int) -> str:
    """The same graph, every node in a process of its own (``--processes``)."""
    return _lockstep(repeat, ["--processes"])


def _realtime_run(extra: list[str]) -> dict[str, float]:
    """One real-time graph run of 20 s: the device's statistics (``stats_file``)."""
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        launch_graph(
            graph_args(extra),
            [
                "device_node:clock_mode=realtime",
                "device_node:duration_s=20.0",
                f"device_node:stats_file={stats}",
            ],
            300,
        )
        with open(stats, encoding="utf-8") as fh:
            result: dict[str, float] = json.load(fh)
            return result


def _realtime(repeat: int, extra: list[str]) -> str:
    runs = [around(lambda: _realtime_run(extra), GRAPH_ARGS) for _ in range(repeat)]
    rows = [r for r, _ in runs]
    med = {
        k: statistics.median(r[k] for r in rows)
        for k in ("on_time_pct", "latency_p50_ms", "latency_p99_ms", "missed_ticks")
    }
    batch = statistics.median(r["latency_p50_ms"] * 1e3 / f.batch_us for r, f in runs)
    hop = statistics.median(r["latency_p50_ms"] * 1e3 / f.hop_us for r, f in runs)
    on_time = ", ".join(f"{r['on_time_pct']:.2f}" for r in rows)
    return (
        f"commands before the next tick: median {med['on_time_pct']:.2f} % (runs: "
        f"{on_time}); sample-to-command latency p50 {med['latency_p50_ms']:.3f} ms "
        f"({batch:.2f}x the batch cycle, {hop:.2f}x one hop), p99 "
        f"{med['latency_p99_ms']:.3f} ms; missed ticks {med['missed_ticks']:g} of 20000 "
        f"({summary([f for _, f in runs])})"
    )


def bench_realtime(repeat: int) -> str:
    """The graph in real time at 1 kHz for 20 s, laid out by default (the loop in one
    process): on-time share and latency."""
    return _realtime(repeat, [])


def bench_realtime_composed(repeat: int) -> str:
    """The same, every node in one process (``--composed``)."""
    return _realtime(repeat, ["--composed"])


def bench_realtime_processes(repeat: int) -> str:
    """The same, every node in a process of its own (``--processes``)."""
    return _realtime(repeat, ["--processes"])
