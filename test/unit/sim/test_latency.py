"""The device's latency statistics: constant memory, percentiles exact to one bin."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.runtime.latency import LatencyHistogram


def test_percentiles_match_numpy_to_one_bin() -> None:
    rng = np.random.default_rng(3)
    lat = rng.gamma(2.0, 3e-4, 20_000)
    h = LatencyHistogram()
    for x in lat:
        h.add(float(x))
    ordered = np.sort(lat)
    for q in (50, 90, 99, 99.9):
        # the nearest-rank percentile, read at its bin's upper edge: within one bin above it
        exact = ordered[math.ceil(q / 100 * lat.size) - 1]
        assert exact <= h.percentile(q) <= exact + h.resolution_s + 1e-12
    assert h.counts.nbytes < 1_000_000 and h.n == lat.size


def test_empty_overflow_and_negative() -> None:
    h = LatencyHistogram(resolution_s=1e-3, max_s=0.01)
    assert math.isnan(h.percentile(50))
    h.add(-1.0)  # clock skew: counts as zero
    h.add(5.0)  # beyond max_s: the last bin
    assert h.percentile(0) == pytest.approx(1e-3)
    assert h.percentile(100) == pytest.approx(0.011)
    with pytest.raises(ValueError):
        LatencyHistogram(resolution_s=0.0)
