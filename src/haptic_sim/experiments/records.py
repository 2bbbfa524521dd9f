"""Typed results of the node-graph parts (chapters 7 and 6) and the container of all results.

A graph run measures one ``Cell``; its bag's analysis is a ``RunAnalysis`` (the figures of
``haptic-analyze --json`` the report uses, under the same names). ``Ch7Result`` and ``Ch6Result``
are what the two parts tabulate from their runs; ``ExperimentResults`` is ``results.json``: the
settings of the experiment and each part's result under the part's name.
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Any

from haptic_sim.experiments.jsonio import from_json


def label(mode: str, kf: float) -> str:
    """``OL``, ``CL Kf=2``..."""
    return mode if mode == "OL" else f"{mode} Kf={kf:g}"


@dataclass(frozen=True)
class Cell:
    """What a graph run measures: its part, the controller (mode, Kf) and the wall (N/m)."""

    part: str
    mode: str
    kf: float
    wall: float


#: the fields of a ``RunAnalysis`` that say which run it is; the others are the bag's figures
_RUN_FIELDS = ("part", "mode", "kf", "wall", "name", "segments", "bag")


@dataclass(frozen=True)
class RunAnalysis:
    """One run's bag as ``haptic-analyze`` sees it: its cell and its longest segment's figures.

    The figures keep ``haptic-analyze``'s names and units; None where it gives none.
    """

    part: str
    mode: str
    kf: float
    wall: float  # N/m, as planned
    name: str
    segments: int  # segments in the bag
    bag: str
    controller: str | None = None
    stiffness_n_per_m: float | None = None  # as recorded
    bandwidth_hz: float | None = None
    band_limited_by_fmax: bool | None = None
    band_below_first_bin: bool | None = None
    impedance_error_pct: float | None = None
    coherence_in_band: float | None = None
    in_contact_pct: float | None = None
    vibrating: bool | None = None
    vibration_amplitude_m: float | None = None
    vibration_frequency_hz: float | None = None
    max_active_energy_j: float | None = None
    perturbation_growth_per_s: float | None = None
    perturbation_vibrates: bool | None = None
    observer_gain: float | None = None
    duration_s: float | None = None
    problem: str | None = None

    @classmethod
    def from_segment(
        cls, cell: Cell, name: str, segments: int, segment: dict[str, Any]
    ) -> RunAnalysis:
        """The run's figures from one segment of ``haptic-analyze --json`` (its own names)."""
        figures = [f.name for f in fields(cls) if f.name not in _RUN_FIELDS]
        return from_json(
            cls,
            {
                "part": cell.part,
                "mode": cell.mode,
                "kf": cell.kf,
                "wall": cell.wall,
                "name": name,
                "segments": segments,
                "bag": segment["bag"],
                **{k: segment.get(k) for k in figures},
            },
        )

    @property
    def controller_label(self) -> str:
        """``OL``, ``CL Kf=2``..."""
        return label(self.mode, self.kf)

    @property
    def where(self) -> str:
        """``CL Kf=2 at 800 N/m``."""
        return f"{self.controller_label} at {self.wall:g} N/m"


@dataclass(frozen=True)
class Check:
    """One acceptance check of the issue: what was compared, and whether it held."""

    text: str
    passed: bool


@dataclass(frozen=True)
class OnsetPoint:
    """One wall of a chapter-6 sweep: the pulse response's growth rate (1/s, None if vibrating
    before the pulse) and whether the wall vibrates."""

    wall: float
    growth_per_s: float | None
    vibrates: bool


@dataclass(frozen=True)
class GraphOnset:
    """One controller's chapter-6 sweep through the graph and its interpolated onset (N/m)."""

    controller: str  # label
    mode: str
    kf: float
    points: list[OnsetPoint]  # by wall
    onset_n_per_m: float | None  # None: nothing vibrated up to the last wall
    first_point_vibrates: bool  # the onset is at or below the lowest wall


@dataclass(frozen=True)
class TapPoint:
    """One wall of chapter 6's tap protocol: the motion 2-3 s after the tap (RMS about its slow
    trend, m; its dominant frequency, Hz) and whether that is a sustained vibration."""

    wall: float
    residual_rms_m: float
    frequency_hz: float
    vibrates: bool


@dataclass(frozen=True)
class TapSweep:
    """One controller's walls under the tap, through the graph, and the first that vibrates."""

    controller: str  # label
    mode: str
    kf: float
    points: list[TapPoint]  # by wall
    first_vibrating_n_per_m: float | None  # None: none of its walls


@dataclass(frozen=True)
class Ch7Result:
    """Chapter 7 through the graph: one analysis per (controller, wall) and the checks."""

    rows: list[RunAnalysis]
    checks: list[Check]


@dataclass(frozen=True)
class Ch6Result:
    """Chapter 6 through the graph: one analysis per (controller, wall) of both protocols, the
    linear protocol's onsets, the tap's sweeps, and the checks."""

    rows: list[RunAnalysis]
    onsets: list[GraphOnset]  # per controller, the linear protocol
    taps: list[TapSweep]  # per controller, the tap with the configuration's friction
    checks: list[Check]


@dataclass(frozen=True)
class ExperimentResults:
    """``results.json``: the settings of one ``haptic-experiment`` and every part's result."""

    config: str  # the base config as given
    config_params: dict[str, dict[str, Any]]  # its node parameters
    quick: bool
    seed: int  # of the hand motion
    parts: list[str]  # as asked for
    results: dict[str, Any]  # part name -> its result (the part's ``result_type``)
    timing_s: dict[str, float]  # wall time per stage (s)
