"""The thesis's own numbers, shown beside the simulation's: Tables 7.1 and 7.2, the chapter-6 walls.

These are the only numbers of the report typed in rather than measured. They are held out: no
parameter of the simulation or of the experiments is read from them (``test_held_out``); the
report only sets the measurements beside them.
"""

from __future__ import annotations

from haptic_sim.experiments.plan import CH7_WALLS

#: the walls of Tables 7.1 and 7.2 (N/m): chapter 7's (thesis 7.1)
WALLS: tuple[float, ...] = tuple(CH7_WALLS)
#: Table 7.1, transparency bandwidth (Hz) per (mode, Kf), one value per wall of ``WALLS``
BANDWIDTH_HZ: dict[tuple[str, float], tuple[float, ...]] = {
    ("OL", 0.0): (1.3, 3.8, 5.3, 0.6),
    ("CL", 2.0): (1.7, 5.5, 6.6, 4.5),
    ("DOB", 1.0): (1.6, 5.1, 6.0, 5.3),
    ("DOB", 25.0): (1.8, 2.9, 3.9, 3.4),
}
#: Table 7.2, average impedance error in the band (%), as ``BANDWIDTH_HZ``
ERROR_PCT: dict[tuple[str, float], tuple[float, ...]] = {
    ("OL", 0.0): (26.8, 30.5, 27.0, 29.0),
    ("CL", 2.0): (25.4, 30.4, 22.8, 16.5),
    ("DOB", 1.0): (23.9, 34.0, 30.9, 26.6),
    ("DOB", 25.0): (40.3, 32.0, 26.0, 22.7),
}
#: chapter 6: the lowest wall that vibrated (N/m) per mode
ONSET_N_PER_M: dict[str, float] = {"OL": 2400.0, "CL": 800.0, "DOB": 3200.0}


def cell(mode: str, kf: float, wall: float) -> tuple[float | None, float | None]:
    """The thesis's (bandwidth Hz, impedance error %) of a chapter-7 cell, None if not there."""
    if (mode, kf) not in BANDWIDTH_HZ or wall not in WALLS:
        return None, None
    i = WALLS.index(wall)
    return BANDWIDTH_HZ[(mode, kf)][i], ERROR_PCT[(mode, kf)][i]


#: a simulated bandwidth matches the thesis's when within this of it (relative)
WITHIN = 0.15


def within(mode: str, kf: float, wall: float, bandwidth_hz: float | None) -> bool:
    """``bandwidth_hz`` within ``WITHIN`` of Table 7.1's cell (False if either is None)."""
    ref = cell(mode, kf, wall)[0]
    return ref is not None and bandwidth_hz is not None and abs(bandwidth_hz - ref) <= WITHIN * ref
