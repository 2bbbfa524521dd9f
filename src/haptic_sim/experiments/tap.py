"""Chapter 6's tap protocol through the graph: does a wall keep vibrating with the plant's friction?

DOB with Kf = 100 is linearly unstable at every wall (``haptic_dob.analysis.linear_loop``): what
keeps it quiet, if anything, is the plant's friction and the actuator's saturation, which the
linear protocol leaves out. The tap protocol (``haptic_sim.slide.stability.TAP``) keeps the
configuration's plant and observer model as they are and taps the handle with 3 N for 20 ms; each
run's bag gives the motion 2-3 s after the tap (RMS about its slow trend, from the encoder's
``ee_pose``), and a wall vibrates when the hand would feel that motion (``felt``: its peak above
the vibrotactile detection threshold at its frequency). OL and CL are tapped too:
with friction they keep no vibration, which is why their onsets come from the linear protocol.
"""

from __future__ import annotations

import numpy as np

from haptic_dob.bag.reader import Selection, read_bag
from haptic_sim.experiments import thesis
from haptic_sim.experiments.records import Check, RunAnalysis, TapPoint, TapSweep, label
from haptic_sim.slide.stability import TAP, StabilityProtocol, felt, residual

#: the DOB onset is compared with the thesis's within this (relative)
WITHIN = 0.15


def tap_point_of(
    wall: float, t_s: np.ndarray, x_m: np.ndarray, rate_hz: float, protocol: StabilityProtocol = TAP
) -> TapPoint:
    """The residual motion of a tap session's record (times in s, positions in m): its last
    second, 2-3 s after the tap."""
    end = protocol.duration_s
    last = np.asarray(x_m, dtype=np.float64)[(t_s >= end - 1.0) & (t_s < end)]
    rms, freq = residual(last, rate_hz, 0.0, last.size / rate_hz)
    return TapPoint(wall, rms, freq, felt(rms, freq))


def tap_point(row: RunAnalysis, rate_hz: float) -> TapPoint:
    """The residual motion of one tap run, from its bag's ``ee_pose`` (the encoder)."""
    motion = read_bag(row.bag, Selection()).motion
    return tap_point_of(row.wall, motion.stamps_ns * 1e-9, motion.values, rate_hz)


def tap_sweeps(points: dict[tuple[str, float], list[TapPoint]]) -> list[TapSweep]:
    """Per controller (in the order given), its walls and the first that vibrates."""
    out = []
    for (mode, kf), pts in points.items():
        by_wall = sorted(pts, key=lambda p: p.wall)
        first = next((p.wall for p in by_wall if p.vibrates), None)
        out.append(TapSweep(label(mode, kf), mode, kf, by_wall, first))
    return out


def tap_result(rows: list[RunAnalysis], rate_hz: float) -> list[TapSweep]:
    """The tap runs' sweeps, each bag read for its residual motion."""
    points: dict[tuple[str, float], list[TapPoint]] = {}
    for r in rows:
        points.setdefault((r.mode, r.kf), []).append(tap_point(r, rate_hz))
    return tap_sweeps(points)


def tap_checks(taps: list[TapSweep]) -> list[Check]:
    """DOB's first vibrating wall against the thesis's onset (3200 N/m) within ``WITHIN``; OL and
    CL keep no vibration with the plant's friction (the linear protocol's premise)."""
    checks = []
    quiet = [t for t in taps if t.mode in ("OL", "CL")]
    if quiet:
        walls = "; ".join(f"{t.controller} at {_walls(t)}" for t in quiet)
        checks.append(
            Check(
                "with the plant's friction, OL and CL keep no vibration after the tap ("
                + walls
                + "): their onsets need the linear protocol, friction left out",
                all(t.first_vibrating_n_per_m is None for t in quiet),
            )
        )
    for t in taps:
        if t.mode != "DOB":
            continue
        ref = thesis.ONSET_N_PER_M["DOB"]
        got = t.first_vibrating_n_per_m
        shown = "none" if got is None else f"{got:g} N/m"
        checks.append(
            Check(
                f"{t.controller} with the plant's friction, tapped: the first wall that keeps "
                f"vibrating ({shown}; walls {_walls(t)}) within +-{WITHIN:.0%} of the thesis's "
                f"{ref:g} N/m",
                got is not None and abs(got - ref) <= WITHIN * ref,
            )
        )
    return checks


def _walls(t: TapSweep) -> str:
    return ", ".join(f"{p.wall:g}" for p in t.points) + " N/m"
