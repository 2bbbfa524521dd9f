"""Latency statistics in constant memory: a fixed-bin histogram with percentiles.

A real-time device runs for hours at 1 kHz; keeping every latency would grow without bound. The
histogram has ``resolution_s`` bins up to ``max_s`` (1 us up to 50 ms by default, 400 kB) and
counts anything longer in the last bin; percentiles are read at a bin's upper edge, so they are
exact to one resolution step (and a lower bound above ``max_s``).
"""

from __future__ import annotations

import math

import numpy as np


class LatencyHistogram:
    """Counts of latencies (s) in fixed bins; ``percentile(q)`` in seconds."""

    def __init__(self, resolution_s: float = 1e-6, max_s: float = 0.05) -> None:
        if not (resolution_s > 0.0 and max_s > resolution_s):
            raise ValueError("need 0 < resolution_s < max_s")
        self.resolution_s = resolution_s
        self.counts = np.zeros(math.ceil(max_s / resolution_s) + 1, dtype=np.int64)
        self.n = 0

    def add(self, latency_s: float) -> None:
        """Count one latency (negative values count as zero)."""
        i = int(max(latency_s, 0.0) / self.resolution_s)
        self.counts[min(i, self.counts.size - 1)] += 1
        self.n += 1

    def percentile(self, q: float) -> float:
        """The ``q``-th percentile (0-100) in seconds; NaN when nothing was counted."""
        if self.n == 0:
            return math.nan
        rank = max(1, math.ceil(q / 100.0 * self.n))
        i = int(np.searchsorted(np.cumsum(self.counts), rank))
        return (i + 1) * self.resolution_s
