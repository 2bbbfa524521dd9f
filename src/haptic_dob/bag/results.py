"""Typed results of a bag's analysis: ``SegmentResult`` per labelled segment, ``BagAnalysis``."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

from haptic_dob.analysis.figures import Figures
from haptic_dob.analysis.vibration import PerturbationResponse
from haptic_dob.bag.resample import Record
from haptic_dob.bag.segments import Segment


@dataclass
class SegmentResult:
    """One labelled segment of a bag and its figures."""

    bag: str
    segment: Segment
    start_s: float  # stamp time of the first sample (s)
    end_s: float  # stamp time after the last sample (s)
    analysed_from_s: float  # start of the analysed part (s)
    analysed_s: float  # length of the analysed part (s)
    stiffness_n_per_m: float | None
    stiffness_source: str  # "recorded", "--stiffness" or "unknown"
    damping_n_s_per_m: float
    figures: Figures
    record: Record = field(repr=False)
    window: slice = field(repr=False)
    perturbation: PerturbationResponse | None = None  # push-and-hold sessions: the pulse's answer

    @property
    def controller(self) -> str:
        """OL, CL, DOB or '?' when no controller parameters were recorded."""
        mode = self.segment.value("controller_node", "mode")
        return str(mode) if mode is not None else "?"

    @property
    def kf(self) -> float | None:
        """Force-feedback gain (None if unknown)."""
        kf = self.segment.value("controller_node", "kf")
        return None if kf is None else float(kf)

    @property
    def label(self) -> str:
        """``DOB Kf=1, 800 N/m`` style label."""
        c = self.controller
        kf = self.kf
        ctl = c if c in ("OL", "?") or kf is None else f"{c} Kf={kf:g}"
        k = self.stiffness_n_per_m
        return f"{ctl}, {k:g} N/m" if k is not None else f"{ctl}, K unknown"

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready figures (SI units in the names; None where not available)."""
        f = self.figures
        tr, en, osc = f.transparency, f.energy, f.oscillation
        seg = self.segment
        return {
            "bag": self.bag,
            "segment": seg.index,
            "controller": self.controller,
            "kf": self.kf,
            "stiffness_n_per_m": self.stiffness_n_per_m,
            "stiffness_source": self.stiffness_source,
            "damping_n_s_per_m": self.damping_n_s_per_m,
            "observer_gain": _num(seg.value("observer_node", "gain")),
            "observer_output_limit": _num(seg.value("observer_node", "output_limit")),
            "start_s": self.start_s,
            "end_s": self.end_s,
            "duration_s": self.end_s - self.start_s,
            "analysed_from_s": self.analysed_from_s,
            "analysed_s": self.analysed_s,
            "bandwidth_hz": None if tr is None else tr.bandwidth_hz,
            "band_limited_by_fmax": None if tr is None else tr.band_limited_by_fmax,
            "band_below_first_bin": None if tr is None else tr.band_below_first_bin,
            "impedance_error_pct": None if tr is None else _num(tr.impedance_error_pct),
            "coherence_in_band": None if tr is None else _num(tr.mean_coherence_in_band),
            "in_contact_pct": f.in_contact_pct,
            "vibrating": None if osc is None else osc.vibrating,
            "vibration_amplitude_m": None if osc is None else _num(osc.amplitude_m),
            "vibration_frequency_hz": None if osc is None else _num(osc.frequency_hz),
            "vibration_growth_per_s": None if osc is None else _num(osc.growth_per_s),
            "vibration_peak_fraction": None if osc is None else _num(osc.peak_fraction),
            "vibrating_s": None if osc is None else osc.vibrating_s,
            "max_active_energy_j": en.max_active_j,
            "max_active_at_s": (
                self.analysed_from_s + en.t_max_active_s if en.max_active_j > 0 else None
            ),
            "final_energy_j": en.final_j,
            "perturbation_growth_per_s": None
            if self.perturbation is None
            else _num(self.perturbation.growth_per_s),
            "perturbation_vibrates": None
            if self.perturbation is None
            else self.perturbation.vibrates,
            "missing_samples": self.record.missing,
            "sample_rate_hz": self.record.fs_hz,
            "parameters": seg.params,
            "problem": f.problem,
        }


def _num(v: Any) -> float | None:
    if v is None:
        return None
    v = float(v)
    return v if math.isfinite(v) else None


@dataclass
class BagAnalysis:
    """Every segment of one bag."""

    path: str
    storage: str
    motion_topic: str
    force_topic: str
    velocity_source: str
    segments: list[SegmentResult]
