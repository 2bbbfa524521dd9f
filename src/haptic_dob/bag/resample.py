"""Resampling: a bag's motion, hand force and velocity as one ``Record`` on a uniform grid.

The loop stamps sample k with ``k * T`` on every topic, so motion and force normally share their
stamps exactly and are simply paired. Otherwise (another driver, a lost message) the force is
taken at the motion stamps it shares when they are at least 99 % of them, else interpolated
linearly onto the motion stamps. The spectral analysis needs a uniform grid: the period is the
median stamp step, and missing grid points (gaps) are filled by linear interpolation and counted.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from haptic_dob.bag.errors import BagError
from haptic_dob.bag.reader import BagData
from haptic_dob.bag.series import Series

MIN_SHARED = 0.99  # fraction of motion stamps the force must share to pair them exactly


@dataclass
class Record:
    """Motion x (m or rad), hand force F (N) and velocity v on a uniform grid ``t0 + k dt``."""

    t0_ns: int
    dt_ns: int
    x: np.ndarray
    force: np.ndarray
    velocity: np.ndarray
    recv_ns: np.ndarray  # bag (log) time of each grid point, non-decreasing
    missing: int  # grid points without a motion or force sample of their own (interpolated)
    velocity_source: str  # topic, or "difference of <motion topic>"

    @property
    def fs_hz(self) -> float:
        """Sample rate (Hz)."""
        return 1e9 / self.dt_ns

    @property
    def size(self) -> int:
        """Number of samples."""
        return int(self.x.size)

    def time_s(self, index: int | np.ndarray) -> float | np.ndarray:
        """Stamp time (s) of sample ``index``."""
        return (self.t0_ns + np.asarray(index) * self.dt_ns) * 1e-9


def _on_stamps(base: np.ndarray, other: Series) -> tuple[np.ndarray, np.ndarray]:
    """(mask of base stamps kept, other's values at them): exact pairing or interpolation."""
    if np.array_equal(base, other.stamps_ns):
        return np.ones(base.size, bool), other.values
    idx = np.searchsorted(other.stamps_ns, base)
    idx_c = np.minimum(idx, other.stamps_ns.size - 1)
    exact = other.stamps_ns[idx_c] == base
    if exact.mean() >= MIN_SHARED:
        return exact, other.values[idx_c[exact]]
    inside = (base >= other.stamps_ns[0]) & (base <= other.stamps_ns[-1])
    vals = np.interp(
        base[inside].astype(np.float64), other.stamps_ns.astype(np.float64), other.values
    )
    return inside, vals


def build_record(data: BagData) -> Record:
    """Pair force and velocity with the motion and put all three on a uniform grid."""
    m = data.motion
    stamps = m.stamps_ns
    keep, force = _on_stamps(stamps, data.force)
    if keep.sum() < 2:
        raise BagError(
            f"{data.path}: the force topic {data.force.topic} and the motion topic {m.topic} "
            "do not overlap in time"
        )
    x, recv = m.values, m.recv_ns
    if not keep.all():
        stamps, x, recv = stamps[keep], x[keep], recv[keep]
    if data.velocity is not None:
        vkeep, v = _on_stamps(stamps, data.velocity)
        if vkeep.all():
            velocity, source = v, data.velocity.topic
        else:
            velocity, source = None, ""
    else:
        velocity, source = None, ""
    steps = np.diff(stamps)
    dt = int(np.median(steps))
    if dt <= 0:
        raise BagError(f"{data.path}: the stamps of {m.topic} do not advance")
    n = int((stamps[-1] - stamps[0]) // dt) + 1
    grid_needed = not (n == stamps.size and bool(np.all(steps == dt)))
    missing = 0
    if grid_needed:
        grid = stamps[0] + np.arange(n, dtype=np.int64) * dt
        missing = max(0, n - stamps.size)
        g, s = grid.astype(np.float64), stamps.astype(np.float64)
        x = np.interp(g, s, x)
        force = np.interp(g, s, force)
        recv = np.interp(g, s, recv.astype(np.float64)).astype(np.int64)
        if velocity is not None:
            velocity = np.interp(g, s, velocity)
    if velocity is None:  # backward difference, as an encoder's velocity
        velocity = np.empty_like(x)
        velocity[0] = 0.0
        velocity[1:] = np.diff(x) / (dt * 1e-9)
        source = f"difference of {m.topic}"
    if not bool(np.all(recv[1:] >= recv[:-1])):
        recv = np.maximum.accumulate(recv)
    return Record(int(stamps[0]), dt, x, force, velocity, recv, missing, source)
