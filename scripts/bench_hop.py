"""The DDS floor of one hop: a ping-pong of a small raw message between two rclpy processes.

``haptic_dob.runtime.ros.dds_hop`` measures it (each side a process with an events executor and
the loop's QoS); ``hop_us`` is also the floor ``benchmarks.py margin`` compares the 4-process
graph with, and the real-time tests of that layout check it first (``test/support/capacity.py``).
"""

from __future__ import annotations

import statistics

from haptic_dob.runtime.ros.dds_hop import hop_us


def bench_hop(repeat: int) -> str:
    """The DDS floor of one hop between two processes (ping-pong, events executor)."""
    hops = [hop_us() for _ in range(repeat)]
    return (
        f"one hop median {statistics.median(hops):.0f} us (runs: "
        f"{', '.join(f'{h:.0f}' for h in hops)})"
    )
