"""The DDS floor of one hop: a ping-pong of a small raw message between two rclpy processes.

What DDS and rclpy alone cost a message between two processes on this machine, now (the
process wake-ups on each side included): the floor the 4-process loop is measured against in
the benchmarks (``scripts/bench_margin.py``), and part of the premise the real-time tests of
that layout check before they ask for 1 kHz (``test/support/capacity.py``). Each side is a process
with an events executor and the loop's QoS, on the domain id it is given, localhost only.
"""

from __future__ import annotations

import multiprocessing
import os
import queue
import random
import statistics
import time
from collections.abc import Callable
from typing import Any

from haptic_msgs_py import wire

WARM_UP = 0.1  # share of the round trips left out at the start
Peer = tuple[Callable[..., None], tuple[Any, ...]]  # a process's target and its arguments


def peer_node(name: str, domain: str) -> tuple[Any, Any, Any]:
    """(context, node, events executor) of a benchmark process on ``domain``, localhost only."""
    os.environ["ROS_DOMAIN_ID"] = domain
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    # lazy: only the peer processes load rclpy, their callers stay ROS-free
    import rclpy
    from rclpy.context import Context
    from rclpy.experimental.events_executor import EventsExecutor

    ctx = Context()
    rclpy.init(context=ctx, args=[])
    return ctx, rclpy.create_node(name, context=ctx), EventsExecutor(context=ctx)


def _hop_peer(role: str, n: int, domain: str, out: Any) -> None:
    """One side of the ping-pong: ``a`` sends and times, ``b`` echoes (raw bytes, events
    executor, the loop's QoS: reliable volatile publisher, best-effort subscription as the
    sensor streams take it)."""
    ctx, node, ex = peer_node(f"hop_{role}", domain)
    # lazy: only the peer processes load rclpy
    from std_msgs.msg import Header

    from haptic_msgs_py.ros.qos import LOOP, LOOP_IN_BEST_EFFORT

    send, receive = ("ping", "pong") if role == "a" else ("pong", "ping")
    pub = node.create_publisher(Header, send, LOOP)
    state: dict[str, float] = {"got": 0, "t": 0.0}
    rtts: list[float] = []
    data = wire.encode(wire.header("base_link"))

    def on_data(msg: bytes) -> None:
        if role == "b":
            pub.publish(msg)
        else:
            rtts.append(time.perf_counter() - state["t"])
            state["got"] += 1

    node.create_subscription(Header, receive, on_data, LOOP_IN_BEST_EFFORT, raw=True)
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


def run_peers(waiter: Peer, other: Peer, timeout_s: float, what: str) -> Any:
    """Start ``other`` then ``waiter`` (each a target and its arguments) in spawned processes,
    ``waiter`` given a result queue as its last argument; return the result it puts, then stop
    both. ``RuntimeError`` naming ``what`` when either ends with no result, or none comes
    within ``timeout_s``."""
    ctx = multiprocessing.get_context("spawn")
    out = ctx.Queue()
    second = ctx.Process(target=other[0], args=other[1])
    second.start()
    first = ctx.Process(target=waiter[0], args=(*waiter[1], out))
    first.start()
    deadline = time.monotonic() + timeout_s
    try:
        while True:
            try:
                return out.get(timeout=0.5)
            except queue.Empty:
                pass
            ended = [p.exitcode for p in (first, second) if p.exitcode is not None]
            if ended or time.monotonic() > deadline:
                try:
                    return out.get(timeout=1.0)  # put just before its process ended
                except queue.Empty:
                    why = f"a process ended (exit code {ended[0]})" if ended else "timed out"
                    raise RuntimeError(f"{what} gave no result: {why}") from None
    finally:
        first.join(10)
        second.terminate()
        second.join(10)
        for p in (first, second):
            if p.is_alive():
                p.kill()
                p.join(5)


def hop_us(n: int = 3000, domain_id: int | None = None) -> float:
    """Median one-way latency (µs) of a small raw message between two rclpy processes: half the
    round trip of a ping-pong of ``n`` messages, the first 10 % left out (warm-up), on
    ``domain_id`` (None: a random one of 101-200)."""
    domain = str(random.randint(101, 200) if domain_id is None else domain_id)
    echo: Peer = (_hop_peer, ("b", n, domain, None))
    rtts = run_peers((_hop_peer, ("a", n, domain)), echo, 120.0 + n * 0.01, "the ping-pong")
    kept = rtts[int(len(rtts) * WARM_UP) :]
    if not kept:
        raise RuntimeError("the ping-pong got no answer")
    return float(statistics.median(kept)) / 2 * 1e6
