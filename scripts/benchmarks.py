"""Benchmarks of the suite (not timed tests): each prints medians over repeated runs.

Usage: ``.venv/bin/python scripts/benchmarks.py [NAME ...] [--repeat N]``; without names, all
in-process benchmarks run. BENCHMARKS.md records the figures with the exact command and machine.
"""

from __future__ import annotations

import argparse
import os
import platform
import statistics
import sys
import time
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
from bench_pattern import pattern_cycle_us, peer_node


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


def bench_batch_session(repeat: int) -> str:
    """A 40 s slide session at 1 kHz (default config, OL and DOB): real-time factor."""
    from haptic_sim.session import SessionConfig, run_session
    from haptic_sim.stability import law_for

    out = []
    for mode, kf in (("OL", 0.0), ("DOB", 1.0)):
        cfg = SessionConfig().replace(law=law_for(mode, kf))
        times = []
        for _ in range(repeat):
            t0 = time.perf_counter()
            run_session(cfg)
            times.append(time.perf_counter() - t0)
        med = statistics.median(times)
        out.append(f"{mode}: median {med:.3f} s for 40 s simulated -> {40.0 / med:.1f}x real time")
    return "; ".join(out)


def bench_observer_update(repeat: int) -> str:
    """One slide observer update (validation, implicit update, clip): microseconds."""
    import timeit

    from haptic_dob.models import SlideModel
    from haptic_dob.observer import DisturbanceObserver

    obs = DisturbanceObserver(SlideModel(), 41.6, 1e-3, 4.0)
    q, qd, tau = (0.001,), (0.01,), (0.5,)
    obs.update(q, qd, tau)
    n = 100_000
    runs = [
        timeit.timeit(lambda: obs.update(q, qd, tau), number=n) / n * 1e6 for _ in range(repeat)
    ]
    return f"median {statistics.median(runs):.2f} us per update (min {min(runs):.2f})"


def batch_cycle_us(mode: str = "DOB", kf: float = 1.0, seconds: float = 10.0) -> float:
    """One batch slide session's time per cycle (µs): the maths of the loop with no transport."""
    from haptic_sim.session import SessionConfig, run_session
    from haptic_sim.stability import law_for

    cfg = SessionConfig().replace(law=law_for(mode, kf), loop__duration_s=seconds)
    t0 = time.perf_counter()
    run_session(cfg)
    return (time.perf_counter() - t0) / (seconds * 1e3) * 1e6


def _hop_peer(role: str, n: int, domain: str, out: Any) -> None:
    """One side of the ping-pong: ``a`` sends and times, ``b`` echoes (raw bytes, events
    executor, the loop's QoS: reliable transient-local publisher, best-effort subscription)."""
    ctx, node, ex = peer_node(f"hop_{role}", domain)
    from std_msgs.msg import Header

    from haptic_msgs_py import wire
    from haptic_msgs_py.ros.qos import LOOP, LOOP_IN

    send, receive = ("ping", "pong") if role == "a" else ("pong", "ping")
    pub = node.create_publisher(Header, send, LOOP)
    state = {"got": 0}
    rtts: list[float] = []
    data = wire.encode(wire.header("base_link"))

    def on_data(msg: bytes) -> None:
        if role == "b":
            pub.publish(msg)
        else:
            rtts.append(time.perf_counter() - state["t"])
            state["got"] += 1

    node.create_subscription(Header, receive, on_data, LOOP_IN, raw=True)
    ex.add_node(node)
    end = time.monotonic() + 30.0
    while pub.get_subscription_count() < 1 and time.monotonic() < end:
        ex.spin_once(timeout_sec=0.01)
    if role == "b":
        end = time.monotonic() + 60.0 + n * 0.01
        while time.monotonic() < end and ctx.ok():
            ex.spin_once(timeout_sec=0.05)
        return
    time.sleep(0.5)  # the echo's publisher matched too
    for _ in range(n):
        state["t"] = time.perf_counter()
        before = state["got"]
        pub.publish(data)
        limit = time.monotonic() + 1.0
        while state["got"] == before and time.monotonic() < limit:
            ex.spin_once(timeout_sec=0.1)
    out.put(rtts)


def hop_us(n: int = 3000) -> float:
    """Median one-way latency (µs) of a small raw message between two rclpy processes: half the
    round trip of a ping-pong, the first 10 % left out (warm-up)."""
    import multiprocessing
    import random

    ctx = multiprocessing.get_context("spawn")
    out = ctx.Queue()
    domain = str(random.randint(101, 200))
    echo = ctx.Process(target=_hop_peer, args=("b", n, domain, out))
    echo.start()
    timer = ctx.Process(target=_hop_peer, args=("a", n, domain, out))
    timer.start()
    try:
        rtts = out.get(timeout=120.0 + n * 0.01)
    finally:
        timer.join(10)
        echo.terminate()
        echo.join(10)
    kept = rtts[len(rtts) // 10 :]
    if not kept:
        raise RuntimeError("the ping-pong got no answer")
    return statistics.median(kept) / 2 * 1e6


def bench_hop(repeat: int) -> str:
    """The DDS floor of one hop between two processes (ping-pong, events executor)."""
    hops = [hop_us() for _ in range(repeat)]
    return (
        f"one hop median {statistics.median(hops):.0f} us (runs: "
        f"{', '.join(f'{h:.0f}' for h in hops)})"
    )


def _lockstep_cycle_us(extra: list[str], seconds: float = 20.0) -> float:
    """One lockstep graph run's time per cycle (µs), from the device's real-time factor."""
    import re

    text = _launch(graph_args(extra), [f"device_node:duration_s={seconds}"], 300)
    found = re.search(r"real-time factor ([0-9.]+)", text)
    if found is None:
        raise RuntimeError(f"no real-time factor in the launch output: {text[-1500:]}")
    return 1e3 / float(found.group(1))


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
        c = _lockstep_cycle_us(["--composed", *MARGIN_MODE])
        b2 = batch_cycle_us()
        h1 = hop_us()
        m1 = pattern_cycle_us()
        p = _lockstep_cycle_us(["--processes", *MARGIN_MODE])
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


def bench_pattern(repeat: int) -> str:
    """The loop's message pattern between four processes that do nothing else (µs a cycle)."""
    cycles = [pattern_cycle_us() for _ in range(repeat)]
    return (
        f"cycle median {statistics.median(cycles):.0f} us (runs: "
        f"{', '.join(f'{c:.0f}' for c in cycles)})"
    )


def _launch(extra: list[str], sets: list[str], timeout: float) -> str:
    """Run ``haptic-launch slide_sim`` on a fresh domain; return its combined output."""
    import random
    import subprocess

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


#: extra ``haptic-launch`` arguments of the graph benchmarks (--set, --rt-priority, --pin,
#: --cpu-latency)
GRAPH_ARGS: list[str] = []


def graph_args(extra: list[str]) -> list[str]:
    """A benchmark's arguments and ``GRAPH_ARGS``; ``--pin`` only where every node has a process
    of its own (``--processes``): haptic-launch refuses it for nodes sharing a process."""
    args = [*extra, *GRAPH_ARGS]
    return args if "--processes" in args else [a for a in args if a != "--pin"]


def _lockstep(repeat: int, extra: list[str]) -> str:
    import re

    rtf = []
    for _ in range(repeat):
        text = _launch(graph_args(extra), ["device_node:duration_s=20.0"], 300)
        rtf.append(float(re.search(r"real-time factor ([0-9.]+)", text).group(1)))
    per_cycle_us = 1e3 / statistics.median(rtf)
    return (
        f"real-time factor median {statistics.median(rtf):.2f} (runs: "
        f"{', '.join(f'{r:.2f}' for r in sorted(rtf))}) -> {per_cycle_us:.0f} us per cycle"
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


def _realtime(repeat: int, extra: list[str]) -> str:
    import json
    import tempfile

    rows = []
    for _ in range(repeat):
        with tempfile.TemporaryDirectory() as tmp:
            stats = os.path.join(tmp, "stats.json")
            _launch(
                graph_args(extra),
                [
                    "device_node:clock_mode=realtime",
                    "device_node:duration_s=20.0",
                    f"device_node:stats_file={stats}",
                ],
                300,
            )
            with open(stats, encoding="utf-8") as fh:
                rows.append(json.load(fh))
    med = {
        k: statistics.median(r[k] for r in rows)
        for k in ("on_time_pct", "latency_p50_ms", "latency_p99_ms", "missed_ticks")
    }
    runs = ", ".join(f"{r['on_time_pct']:.2f}" for r in rows)
    return (
        f"commands before the next tick: median {med['on_time_pct']:.2f} % (runs: "
        f"{runs}); sample-to-command latency "
        f"p50 {med['latency_p50_ms']:.3f} ms, p99 {med['latency_p99_ms']:.3f} ms; "
        f"missed ticks {med['missed_ticks']:g} of 20000"
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
    import multiprocessing
    import queue

    from haptic_dob.runtime.cpu_latency import hold

    ctx = multiprocessing.get_context("spawn")
    prio = latency = None
    if "--rt-priority" in GRAPH_ARGS:
        prio = int(GRAPH_ARGS[GRAPH_ARGS.index("--rt-priority") + 1])
    if "--cpu-latency" in GRAPH_ARGS:
        latency = int(GRAPH_ARGS[GRAPH_ARGS.index("--cpu-latency") + 1])
    if prio is not None:  # refused here with the reason, not in each loop's process
        before = os.sched_getscheduler(0), os.sched_getparam(0)
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(prio))
        except (OSError, ValueError) as exc:
            raise ValueError(f"SCHED_FIFO priority {prio} refused ({exc})") from None
        os.sched_setscheduler(0, *before)
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


BENCHMARKS: dict[str, Callable[[int], str]] = {
    "batch": bench_batch_session,
    "observer": bench_observer_update,
    "lockstep": bench_lockstep,
    "lockstep-composed": bench_lockstep_composed,
    "lockstep-processes": bench_lockstep_processes,
    "realtime": bench_realtime,
    "realtime-composed": bench_realtime_composed,
    "realtime-processes": bench_realtime_processes,
    "timer-floor": bench_timer_floor,
    "hop": bench_hop,
    "pattern": bench_pattern,
    "margin": bench_margin,
}


def main(argv: list[str] | None = None) -> int:
    """Run the named benchmarks (default: all) and print one line each."""
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
        "and timer-floor run (haptic-launch option; PM QoS, needs root)",
    )
    a = p.parse_args(argv)
    GRAPH_ARGS[:] = [x for item in a.set for x in ("--set", item)]
    if a.rt_priority is not None:
        GRAPH_ARGS.extend(["--rt-priority", str(a.rt_priority)])
    if a.pin:
        GRAPH_ARGS.append("--pin")
    if a.cpu_latency is not None:
        GRAPH_ARGS.extend(["--cpu-latency", str(a.cpu_latency)])
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
