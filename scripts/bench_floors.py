"""The loop's two floors, measured around each graph run: the batch cycle and one raw DDS hop.

A graph figure means little alone on a machine whose speed drifts within minutes, so every graph
benchmark divides its cycle (or latency) by the batch cycle (``bench_batch``: the loop's maths in
process, no transport) and by one raw hop (``bench_hop``: a ping-pong between two processes),
both measured just before and just after that run, in the same mode (``--set
controller_node:mode=... kf=...``, OL by default as ``slide_sim``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import TypeVar

from bench_batch import batch_cycle_us
from bench_hop import hop_us

T = TypeVar("T")


@dataclass(frozen=True)
class Floors:
    """One batch cycle and one raw hop (µs), each the mean of a measurement before and after."""

    batch_us: float
    hop_us: float

    def ratios(self, us: float) -> str:
        """``us`` against both: ``N.NNx the batch cycle, N.NNx one hop``."""
        return f"{us / self.batch_us:.2f}x the batch cycle, {us / self.hop_us:.2f}x one hop"


def loop_law(graph_args: list[str]) -> tuple[str, float]:
    """The controller's mode and Kf the graph runs with (its ``--set``; ``slide_sim``'s OL, 0)."""
    mode, kf = "OL", 0.0
    for i, arg in enumerate(graph_args[:-1]):
        if arg != "--set":
            continue
        key, _, value = graph_args[i + 1].partition("=")
        if key == "controller_node:mode":
            mode = value
        elif key == "controller_node:kf":
            kf = float(value)
    return mode, kf


def around(run: Callable[[], T], graph_args: list[str]) -> tuple[T, Floors]:
    """``run()`` between two measurements of the floors (the batch cycle in the graph's mode)."""
    mode, kf = loop_law(graph_args)
    b1, h1 = batch_cycle_us(mode, kf), hop_us()
    value = run()
    b2, h2 = batch_cycle_us(mode, kf), hop_us()
    return value, Floors((b1 + b2) / 2, (h1 + h2) / 2)


def summary(floors: list[Floors]) -> str:
    """The floors of a benchmark's runs: their ranges."""
    batch = [f.batch_us for f in floors]
    hop = [f.hop_us for f in floors]
    return (
        f"batch cycle {min(batch):.0f}-{max(batch):.0f} us, one hop {min(hop):.0f}-{max(hop):.0f}"
        " us around the runs"
    )
