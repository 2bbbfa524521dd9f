"""The DDS floor of the loop's message pattern: processes that only pass messages.

Each pattern is a few rclpy processes (events executor, raw bytes of a small message, the loop's
QoS) that pass messages and do nothing else; its cycle is what DDS and rclpy cost for that
pattern with no maths and no node logic. ``loop`` is the messages a slide DOB cycle passes
between ``--processes`` nodes: the device sends pose, twist, joint states and the sensor's
wrench; the environment answers pose + twist, the observer the joint states, one message each;
the controller answers wall + estimate with the command, which releases the device's next
sample (it takes the sensor's wrench too, as in CL). The 4-process lockstep cycle against
(``loop`` + the batch cycle) is what the nodes add. Against the raw hop (``bench_hop``):
``one-message`` is ``loop`` with one device message for both environment and observer; ``ring``
passes one message through three processes (device -> environment -> controller -> device);
``ping-pong`` through two, which should come out at two hops. Used by ``benchmarks.py pattern``
and ``margin``; each process is set up as the hop's (``haptic_dob.runtime.ros.dds_hop.peer_node``).
"""

from __future__ import annotations

import itertools
import multiprocessing
import random
import statistics
import time
from typing import Any

from haptic_dob.runtime.ros.dds_hop import hop_us, peer_node
from haptic_msgs_py import wire

#: role -> (topics it publishes, topics it waits for before answering)
Roles = dict[str, tuple[list[str], list[str]]]

#: pattern name -> its roles (the device times the cycle: it answers the command)
PATTERNS: dict[str, Roles] = {
    "loop": {
        "device": (["pose", "twist", "joint_states", "wrench_measured"], ["effort_command"]),
        "environment": (["wrench_wall"], ["pose", "twist"]),
        "observer": (["wrench_estimate"], ["joint_states"]),
        "controller": (["effort_command"], ["wrench_wall", "wrench_estimate"]),
    },
    "one-message": {
        "device": (["sample"], ["effort_command"]),
        "environment": (["wrench_wall"], ["sample"]),
        "observer": (["wrench_estimate"], ["sample"]),
        "controller": (["effort_command"], ["wrench_wall", "wrench_estimate"]),
    },
    "ring": {
        "device": (["sample"], ["effort_command"]),
        "environment": (["wrench_wall"], ["sample"]),
        "controller": (["effort_command"], ["wrench_wall"]),
    },
    "ping-pong": {
        "device": (["sample"], ["effort_command"]),
        "controller": (["effort_command"], ["sample"]),
    },
}


def _peer(pattern: str, role: str, cycles: int, domain: str, stop: Any, out: Any) -> None:
    """One process of ``pattern``; the device times ``cycles`` cycles and puts the median."""
    ctx, node, ex = peer_node(f"pattern_{role}", domain)
    # lazy: only the peer processes load rclpy
    from std_msgs.msg import Header

    from haptic_msgs_py.ros.qos import ESTIMATOR_IN, LOOP, LOOP_IN, LOOP_IN_BEST_EFFORT

    data = wire.encode(wire.header("base_link"))
    sends, waits = PATTERNS[pattern][role]
    pubs = [node.create_publisher(Header, t, LOOP) for t in sends]
    got: set[str] = set()
    ends: list[float] = []

    def answer() -> None:
        for p in pubs:
            p.publish(data)

    def on(topic: str) -> Any:
        def callback(_msg: bytes) -> None:
            got.add(topic)
            if len(got) == len(waits):
                got.clear()
                if role == "device":
                    ends.append(time.perf_counter())
                    if len(ends) >= cycles:
                        return
                answer()

        return callback

    # the nodes' default input QoS: the device's command input reliable, the sensor streams best
    # effort, the observer's input reliable
    qos = {"observer": ESTIMATOR_IN, "device": LOOP_IN}.get(role, LOOP_IN_BEST_EFFORT)
    for t in waits:
        node.create_subscription(Header, t, on(t), qos, raw=True)
    if pattern == "loop" and role == "controller":  # taken, not waited for
        node.create_subscription(Header, "wrench_measured", lambda _m: None, qos, raw=True)
    ex.add_node(node)
    settle = time.monotonic() + 5.0  # discovery and matching of every endpoint
    while time.monotonic() < settle:
        ex.spin_once(timeout_sec=0.01)
    if role != "device":
        while not stop.is_set() and ctx.ok():
            ex.spin_once(timeout_sec=0.05)
        return
    answer()
    limit = time.monotonic() + 60.0 + cycles * 0.01
    while len(ends) < cycles and time.monotonic() < limit:
        ex.spin_once(timeout_sec=0.1)
    steps = [b - a for a, b in itertools.pairwise(ends)][cycles // 10 :]
    out.put(statistics.median(steps) * 1e6 if steps else None)


def pattern_cycle_us(cycles: int = 5000, pattern: str = "loop") -> float:
    """Median cycle (µs) of ``pattern`` (``PATTERNS``; by default the loop's messages between
    four processes), the first 10 % left out as warm-up."""
    ctx = multiprocessing.get_context("spawn")
    out, stop = ctx.Queue(), ctx.Event()
    domain = str(random.randint(101, 200))
    procs = [
        ctx.Process(target=_peer, args=(pattern, r, cycles, domain, stop, out))
        for r in PATTERNS[pattern]
    ]
    for p in procs:
        p.start()
    try:
        cycle = out.get(timeout=120.0 + cycles * 0.01)
    finally:
        stop.set()
        for p in procs:
            p.join(10)
            if p.is_alive():
                p.terminate()
                p.join(5)
    if cycle is None:
        raise RuntimeError(f"the message pattern {pattern!r} did not turn over")
    return float(cycle)


def bench_pattern(repeat: int) -> str:
    """Each message pattern's cycle (µs), the patterns interleaved round by round, with one raw
    hop measured before and after each round: the ratio of each to as many hops as it passes in
    sequence says what the topology costs beyond the raw hop before any node does anything."""
    hops_in_sequence = {"loop": 3, "one-message": 3, "ring": 3, "ping-pong": 2}
    cycles: dict[str, list[float]] = {name: [] for name in PATTERNS}
    ratios: dict[str, list[float]] = {name: [] for name in PATTERNS}
    for _ in range(repeat):
        h1 = hop_us()
        round_ = {name: pattern_cycle_us(3000, name) for name in PATTERNS}
        hop = (h1 + hop_us()) / 2
        for name, cycle in round_.items():
            cycles[name].append(cycle)
            ratios[name].append(cycle / (hops_in_sequence[name] * hop))

    def median(xs: list[float]) -> float:
        return statistics.median(xs)

    return "; ".join(
        f"{name}: cycle median {median(cycles[name]):.0f} us (runs: "
        f"{', '.join(f'{c:.0f}' for c in cycles[name])}), {median(ratios[name]):.2f}x "
        f"{hops_in_sequence[name]} hops"
        for name in PATTERNS
    )
