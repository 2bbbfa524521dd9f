"""The DDS floor of one hop: a ping-pong of a small raw message between two rclpy processes.

Each side is a ``peer_node`` process (``bench_pattern``: events executor, the loop's QoS);
``hop_us`` is also the floor ``benchmarks.py margin`` compares the 4-process graph with.
"""

from __future__ import annotations

import statistics
import time
from typing import Any

from bench_pattern import peer_node


def _hop_peer(role: str, n: int, domain: str, out: Any) -> None:
    """One side of the ping-pong: ``a`` sends and times, ``b`` echoes (raw bytes, events
    executor, the loop's QoS: reliable volatile publisher, best-effort subscription as the
    sensor streams take it)."""
    ctx, node, ex = peer_node(f"hop_{role}", domain)
    from std_msgs.msg import Header

    from haptic_msgs_py import wire
    from haptic_msgs_py.ros.qos import LOOP, LOOP_IN_BEST_EFFORT

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
