"""What this machine allows any 1 kHz loop: one idle loop per CPU waking at every 1 ms tick.

Uses the graph benchmarks' ``--rt-priority`` and ``--cpu-latency`` (``bench_graph.GRAPH_ARGS``);
each loop is pinned to its CPU, as ``--pin`` places the nodes.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import statistics
import time
from typing import Any

from bench_graph import graph_option
from haptic_dob.runtime.cpu_latency import hold
from haptic_dob.runtime.ros.answer_floor import check_sched

FLOOR_S = 20.0  # length of one timer-floor run (s), as the real-time graph runs
FLOOR_BUDGET_S = 0.5e-3  # a tick woken later than this counts as lost (s)


def _floor_loop(cpu: int, t0: float, priority: int | None, out: Any) -> None:
    """Wake at every 1 ms tick from ``t0`` on ``cpu``; put the indices of ticks woken late.

    No work, no resynchronisation: after a stall the loop wakes at once for every tick it
    overslept, so a stall of L ms shows as about L late ticks, as a stalled node makes a burst.
    """
    os.sched_setaffinity(0, {cpu})
    if priority is not None:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    n = int(FLOOR_S * 1e3)
    late: list[int] = []
    longest = 0.0
    monotonic, sleep = time.monotonic, time.sleep
    for k in range(n):
        due = t0 + k * 1e-3
        while (left := due - monotonic()) > 0.0:
            sleep(left)
        lateness = monotonic() - due
        longest = max(longest, lateness)
        if lateness > FLOOR_BUDGET_S:
            late.append(k)
    out.put((cpu, late, longest))


def bench_timer_floor(repeat: int) -> str:
    """What this machine allows any 1 kHz loop: one idle loop per CPU waking at every tick.

    A tick is lost when a CPU's loop woke more than ``FLOOR_BUDGET_S`` late (the graph's loop
    needs about 0.4 ms of its 1 ms period, on both CPUs). Uses ``--rt-priority`` and
    ``--cpu-latency`` when given (one loop per CPU, pinned, as ``--pin`` places the nodes).
    """
    ctx = multiprocessing.get_context("spawn")
    prio, latency = graph_option("--rt-priority"), graph_option("--cpu-latency")
    check_sched(prio, None)  # refused here with the reason, not in each loop's process
    cpus = sorted(os.sched_getaffinity(0))
    n = int(FLOOR_S * 1e3)
    shares, longest, stalls, per_cpu = [], [], [], []
    fd = None if latency is None else hold(latency)
    try:
        for _ in range(repeat):
            out = ctx.Queue()
            t0 = time.monotonic() + 1.0  # every loop started and pinned by then
            procs = [ctx.Process(target=_floor_loop, args=(c, t0, prio, out)) for c in cpus]
            for pr in procs:
                pr.start()
            try:
                results = [out.get(timeout=FLOOR_S + 60.0) for _ in procs]
            except queue.Empty:
                codes = [pr.exitcode for pr in procs]
                raise RuntimeError(f"a timer loop gave no result (exit codes {codes})") from None
            finally:
                for pr in procs:
                    pr.join(timeout=10.0)
            lost = set().union(*(set(late) for _, late, _ in results))
            shares.append(100.0 * (n - len(lost)) / n)
            longest.append(max(m for _, _, m in results) * 1e3)
            stalls.append(len(lost))
            by_cpu = sorted((cpu, len(late)) for cpu, late, _ in results)
            per_cpu.append("/".join(str(count) for _, count in by_cpu))
    finally:
        if fd is not None:
            os.close(fd)
    held = "" if latency is None else f", CPU latency {latency} us held"
    return (
        f"ticks no CPU woke more than {FLOOR_BUDGET_S * 1e3:g} ms late: median "
        f"{statistics.median(shares):.2f} % (runs: {', '.join(f'{s:.2f}' for s in shares)}); "
        f"lost ticks {', '.join(map(str, stalls))} (per CPU {', '.join(per_cpu)}); longest stall "
        "per run "
        f"{', '.join(f'{m:.1f}' for m in longest)} ms ({len(cpus)} CPUs, "
        f"{'SCHED_FIFO ' + str(prio) if prio else 'default scheduling'}{held})"
    )
