"""The Kalman velocity filter's jerk density, identified from a session's positions alone.

``haptic_dob.core.kalman_velocity`` models each joint as constant acceleration driven by white
jerk of density ``psd``, read to the nearest count. Its one free number, ``psd``, says how
briskly the hand moves the device; it is identified here by maximum likelihood of the filter's
innovations (one-step prediction errors, Gaussian of the steady state's variance) over a
recorded session with the user's hand on the device: one density for every joint that moved,
as one hand moves them all. No force and no model of the device are needed, only the
positions, the counts and the sampling period.
"""

from __future__ import annotations

import itertools
import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray
from scipy import optimize

from haptic_dob.core.kalman_velocity import innovations, steady_gain
from haptic_dob.identification.filters import IdentificationError

MIN_COUNTS = 10  # a joint is fitted when its positions span at least this many counts
SETTLE_S = 0.2  # the filter's start left out of the likelihood, in every run (s)
MIN_RUN_S = 0.3  # a run's length after SETTLE_S for it to count (s): lost samples end runs
MIN_TOTAL_S = 1.0  # the runs' lengths after SETTLE_S, summed, that a fit needs (s)
#: a stretch this long (s) over which no joint steps a count: the device parked or held (an
#: inkwell, before the user takes the stylus), left out as the arm's fits leave it out
HELD_S = 0.5
LOG10_BOUNDS = (-6.0, 12.0)  # the search's bounds on log10(psd)


@dataclass(frozen=True)
class JerkFit:
    """The identified density (units^2/s^5), the joints that moved and were fitted, each
    joint's span in counts, the log-likelihood at the optimum and the sampling period (s)."""

    psd: float
    fitted: tuple[str, ...]
    spans_counts: tuple[float, ...]
    log_likelihood: float
    period_s: float


def log_likelihood(
    psd: float, records: Sequence[NDArray[np.float64]], counts: Sequence[float], period_s: float
) -> float:
    """The innovations' Gaussian log-likelihood summed over the records (after ``SETTLE_S``)."""
    skip = math.ceil(SETTLE_S / period_s)
    total = 0.0
    for y, count in zip(records, counts, strict=True):
        g = steady_gain(psd, count, period_s)
        e = innovations(y, g)[skip:]
        total -= 0.5 * (e.size * math.log(2.0 * math.pi * g.innovation_var))
        total -= 0.5 * float(e @ e) / g.innovation_var
    return total


def segments(stamps_ns: NDArray[np.int64]) -> tuple[float, list[slice]]:
    """The record's sampling period (s, the median interval) and its evenly sampled runs: split
    where an interval is off the period by more than half of it (a lost or a doubled sample)."""
    dt = np.diff(np.asarray(stamps_ns, dtype=np.int64)).astype(np.float64) * 1e-9
    if dt.size == 0:
        raise IdentificationError("the record holds one sample or none")
    period = float(np.median(dt))
    if not period > 0.0:
        raise IdentificationError("the record's stamps do not increase")
    breaks = np.flatnonzero(np.abs(dt - period) > 0.5 * period) + 1
    edges = [0, *breaks.tolist(), len(stamps_ns)]
    return period, [slice(a, b) for a, b in itertools.pairwise(edges)]


def moving_runs(runs: Sequence[slice], q: NDArray[np.float64], period_s: float) -> list[slice]:
    """``runs`` with the stretches of ``HELD_S`` or more where no column of ``q`` changed
    taken out: a parked device's innovations are zero, and would pull the density down."""
    still = np.zeros(len(q), dtype=bool)
    steps = np.concatenate([[True], np.any(np.diff(q, axis=0) != 0.0, axis=1), [True]])
    edges = np.flatnonzero(steps)  # sample i steps from i-1 (the ends count as steps)
    for a, b in itertools.pairwise(edges):  # samples a .. b-1 hold q[a]
        if (b - 1 - a) * period_s >= HELD_S:
            still[a:b] = True
    out = []
    for r in runs:
        keep = np.concatenate([[False], ~still[r], [False]]).astype(np.int8)
        starts = np.flatnonzero(np.diff(keep) == 1)
        ends = np.flatnonzero(np.diff(keep) == -1)
        out += [slice(r.start + a, r.start + b) for a, b in zip(starts, ends, strict=True)]
    return out


def identify_jerk_psd(
    stamps_ns: NDArray[np.int64],
    positions: NDArray[np.float64],
    names: Sequence[str],
    counts: Sequence[float],
) -> JerkFit:
    """Fit one density to the joints (columns of ``positions``) whose positions span
    ``MIN_COUNTS`` counts or more, over the record's evenly sampled runs (``segments``) with the
    device moving (``moving_runs``) long enough (``MIN_RUN_S`` after ``SETTLE_S``),
    ``MIN_TOTAL_S`` in all. ``IdentificationError`` when no joint moved, the runs are too short,
    a joint steps by less than half its count, or the optimum lies on the search's bounds."""
    q = np.asarray(positions, dtype=np.float64)
    if q.ndim != 2 or q.shape != (len(stamps_ns), len(names)) or len(counts) != len(names):
        raise IdentificationError(
            "positions need one row per stamp, and one column and one count per joint"
        )
    period, runs = segments(stamps_ns)
    spans = tuple(float(np.ptp(q[:, j])) / c for j, c in enumerate(counts))
    moved = [j for j, s in enumerate(spans) if s >= MIN_COUNTS]
    if not moved:
        raise IdentificationError(
            f"no joint moved {MIN_COUNTS} counts or more (spans in counts: "
            f"{', '.join(f'{n} {s:.0f}' for n, s in zip(names, spans, strict=True))}): record a "
            "session with the hand moving the device"
        )
    for j in moved:
        steps = np.abs(np.diff(q[:, j]))
        steps = steps[steps > 1e-9 * counts[j]]  # a float's rounding is no step
        if steps.size and steps.min() < 0.5 * counts[j] * (1.0 - 1e-9):
            raise IdentificationError(
                f"{names[j]} steps by {steps.min():.3g}, under half the count given "
                f"({counts[j]:.3g}): give the count it has, the smallest step it takes"
            )
    runs = moving_runs(runs, q, period)
    runs = [r for r in runs if (r.stop - r.start) * period >= SETTLE_S + MIN_RUN_S]
    usable_s = sum((r.stop - r.start) * period - SETTLE_S for r in runs)
    if usable_s < MIN_TOTAL_S:
        raise IdentificationError(
            f"the record's evenly sampled runs of {SETTLE_S + MIN_RUN_S:g} s or more with the "
            f"device moving hold {usable_s:.2g} s after their first {SETTLE_S:g} s, the fit "
            f"needs {MIN_TOTAL_S:g} s (period {1e3 * period:.3g} ms): record longer, with the "
            "hand moving the device, or with fewer states lost"
        )
    records = [q[r, j] for j in moved for r in runs]
    cs = [counts[j] for j in moved for _ in runs]
    res = optimize.minimize_scalar(
        lambda lg: -log_likelihood(10.0**lg, records, cs, period),
        bounds=LOG10_BOUNDS,
        method="bounded",
        options={"xatol": 1e-3},
    )
    lo, hi = LOG10_BOUNDS
    if not (lo + 0.01 < res.x < hi - 0.01):
        raise IdentificationError(
            f"the likelihood is best at the search's bound (psd 1e{res.x:.1f}): check the counts "
            "given and the record's units"
        )
    fitted = tuple(names[j] for j in moved)
    return JerkFit(float(10.0**res.x), fitted, spans, -float(res.fun), period)
