"""Thesis section 5.2 on the PHANToM 1.5 as a part of the experiment: the numbers of its report.

The reproductions are ``haptic_sim.phantom.reproduction``'s (``haptic-phantom-figures``); they draw
``thesis_5_2_1.png`` and ``thesis_5_2_2.png`` while they run.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

from haptic_sim.phantom.reproduction import KF_VALUES, reproduce_free_motion, reproduce_wall


@dataclass(frozen=True)
class PhantomWallCell:
    """5.2.2 at one Kf: the DOB run against the one with the exact force."""

    kf: float
    window_s: float  # the comparison window after the release (s)
    dob_vs_exact_height_max_m: float  # largest height difference in the window (m)
    dob_force_error_rms_n: float  # the observer's tip-force error (N RMS)


@dataclass(frozen=True)
class PhantomResult:
    """The phantom part's result: 5.2.1 (free motion) per joint and 5.2.2 (the wall) per Kf."""

    rms_error_n_m: list[float]  # estimate error against -G per joint (N m RMS)
    gravity_range_n_m: list[float]  # span of the gravity torque per joint (N m)
    wall: list[PhantomWallCell]


def reproduce(figures: Path) -> PhantomResult:
    """Run 5.2.1 and 5.2.2 (their figures go to ``figures``)."""
    free = reproduce_free_motion(figures)
    wall = reproduce_wall(figures)
    cells = []
    for kf in KF_VALUES:
        m = wall[f"kf_{kf:g}"]
        cells.append(
            PhantomWallCell(
                kf, m["window_s"], m["dob_vs_exact_height_max_m"], m["dob_force_error_rms_n"]
            )
        )
    return PhantomResult(free["rms_error_n_m"], free["gravity_range_n_m"], cells)
