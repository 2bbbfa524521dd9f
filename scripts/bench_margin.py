"""The loop's cost against its floors (``benchmarks.py margin``), each ratio within one run.

The floors: the batch cycle (``bench_batch``: the maths with no transport), three raw DDS hops
(``bench_hop``) and the loop's message pattern between four processes (``bench_pattern``).
"""

from __future__ import annotations

import json
import os
import statistics
import tempfile

from bench_batch import batch_cycle_us
from bench_graph import launch_graph, lockstep_cycle_us
from bench_hop import hop_us
from bench_pattern import pattern_cycle_us

MARGIN_MODE = ["--set", "controller_node:mode=DOB", "--set", "controller_node:kf=1.0"]


def bench_margin(repeat: int) -> str:
    """The loop's cost against its floors, in DOB mode, each ratio taken within one run:

    - composed lockstep cycle / batch cycle (batch measured just before and after the graph);
    - 4-process lockstep cycle / (3 raw hops + batch cycle), hops measured before and after;
    - 4-process lockstep cycle / (the loop's message pattern + batch cycle): what the nodes add
      to what DDS costs for the messages a cycle passes (``bench_pattern``).
    """
    composed, processes, nodes = [], [], []
    rows = []
    for _ in range(repeat):
        b1 = batch_cycle_us()
        c = lockstep_cycle_us(["--composed", *MARGIN_MODE])
        b2 = batch_cycle_us()
        h1 = hop_us()
        m1 = pattern_cycle_us()
        p = lockstep_cycle_us(["--processes", *MARGIN_MODE])
        m2 = pattern_cycle_us()
        h2 = hop_us()
        b3 = batch_cycle_us()
        composed.append(c / ((b1 + b2) / 2))
        floor = 3 * (h1 + h2) / 2 + (b2 + b3) / 2
        processes.append(p / floor)
        pattern = (m1 + m2) / 2 + (b2 + b3) / 2
        nodes.append(p / pattern)
        rows.append(
            f"batch {b1:.0f}/{b2:.0f}/{b3:.0f} us, composed {c:.0f} us, hop {h1:.0f}/{h2:.0f} "
            f"us, pattern {m1:.0f}/{m2:.0f} us, 4 processes {p:.0f} us (hop floor {floor:.0f}, "
            f"pattern floor {pattern:.0f})"
        )

    def ratios(xs: list[float]) -> str:
        return f"median {statistics.median(xs):.2f} (runs: {', '.join(f'{r:.2f}' for r in xs)})"

    return (
        f"composed / batch cycle: {ratios(composed)}; 4 processes / (3 hops + batch): "
        f"{ratios(processes)}; 4 processes / (message pattern + batch): {ratios(nodes)}; "
        f"{'; '.join(rows)}"
    )


def bench_realtime_margin(repeat: int) -> str:
    """The 4-process real-time loop against its DDS floor, as ``test_graph_realtime`` runs it
    (OL, the controller taking only the wall force, 3 s at 1 kHz): one raw hop measured just
    before and just after, the graph's median sample-to-command latency over three hops (the
    slower measurement), and the share of commands before the next tick."""
    rows, ratios, on_time = [], [], []
    for _ in range(repeat):
        h1 = hop_us(2000)
        with tempfile.TemporaryDirectory() as tmp:
            stats = os.path.join(tmp, "stats.json")
            sets = [
                "device_node:clock_mode=realtime",
                "device_node:duration_s=3.0",
                f"device_node:stats_file={stats}",
                "controller_node:warm_inputs=false",
            ]
            launch_graph(["--processes"], sets, 300)
            with open(stats, encoding="utf-8") as fh:
                s = json.load(fh)
        h2 = hop_us(2000)
        floor_ms = 3 * max(h1, h2) / 1e3
        ratios.append(s["latency_p50_ms"] / floor_ms)
        on_time.append(s["on_time_pct"])
        rows.append(
            f"hop {h1:.0f}/{h2:.0f} us, p50 {s['latency_p50_ms']:.3f} ms, "
            f"on time {s['on_time_pct']:.1f} %"
        )
    return (
        f"p50 / 3 hops: median {statistics.median(ratios):.2f}; on time: median "
        f"{statistics.median(on_time):.1f} %; {'; '.join(rows)}"
    )
