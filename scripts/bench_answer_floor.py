"""The on-time floor at 1 kHz: states answered in time by a loop of each ``WORK_US`` cost.

``haptic_dob.runtime.ros.answer_floor`` measures it (a driver-like process and an answering one,
events executors, the loop's QoS); the bridge benchmark measures the raw answer's floor (no
work) after each of its sessions, in the same run.
"""

from __future__ import annotations

import statistics

from bench_graph import graph_sched
from haptic_dob.runtime.ros.answer_floor import FLOOR_S, answer_floor

#: (before, after) the answer (us): none (the raw answer), about the Force Dimension DOB
#: session's cycle without the recorder, and with it (docs/devices.md: the cycle's CPU p50
#: 190-260 us before the command's send, the DDS take and write in it, 120-190 after)
WORK_US: tuple[tuple[float, float], ...] = ((0.0, 0.0), (100.0, 50.0), (200.0, 150.0))


def bench_answer_floor(repeat: int) -> str:
    """States answered before the next instant at 1 kHz by a loop of each ``WORK_US`` cost."""
    sched = graph_sched()
    parts = []
    for before, after in WORK_US:
        runs = [answer_floor(1000.0, FLOOR_S, (before, after), sched) for _ in range(repeat)]
        shares = ", ".join(f"{r.on_time_pct:.2f}" for r in runs)
        p50 = statistics.median(r.latency_p50_us for r in runs)
        p99 = statistics.median(r.latency_p99_us for r in runs)
        parts.append(
            f"work {before:g} us before the answer, {after:g} after: on time median "
            f"{statistics.median(r.on_time_pct for r in runs):.2f} % (runs: {shares}), "
            f"state->answer p50 {p50:.0f} us, p99 {p99:.0f} us"
        )
    prio, latency = sched
    how = f"SCHED_FIFO {prio}" if prio else "default scheduling"
    held = "" if latency is None else f", CPU latency {latency} us held"
    return "; ".join(parts) + f" ({how}{held})"
