"""Per-segment transparency, vibration and energy of a recorded session.

``analyze_arrays`` is the whole analysis of one steady stretch from plain arrays (the same
function the bag path and an in-process check call); ``analyze_bag`` reads a bag, labels its
segments with the recorded parameters and analyses each.

Per segment, the first ``settle_s`` (first segment: the hand's ramp-in) or ``transient_s`` (after
a parameter change) are left out, at most a quarter of the segment, as
``SessionResult.summary()`` does. Transparency uses the wall's recorded stiffness and damping
(or ``stiffness_n_per_m`` when given) with ``haptic_dob.analysis.transparency``; the energy is the
passivity observer of hand force and velocity (``haptic_dob.analysis.passivity_observer``).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.analysis.energy import EnergyResult, passivity_observer
from haptic_dob.analysis.transparency import (
    DEFAULT_FMAX_HZ,
    DEFAULT_SEGMENT_S,
    TransparencyResult,
    transparency,
)
from haptic_dob.analysis.vibration import PerturbationResponse, perturbation_response
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.oscillation import Oscillation, OscillationSettings, oscillation
from haptic_dob.bag.reader import AXES, JOINT_STATE, Selection, read_bag
from haptic_dob.bag.record import Record, build_record
from haptic_dob.bag.segments import Segment, parameter_history, split


@dataclass(frozen=True)
class AnalysisSettings:
    """What to leave out and the spectral settings (s, Hz)."""

    fmax_hz: float = DEFAULT_FMAX_HZ
    settle_s: float = 2.0
    transient_s: float = 0.5
    segment_s: float = DEFAULT_SEGMENT_S
    stiffness_n_per_m: float | None = None  # overrides the recorded wall stiffness
    oscillation: OscillationSettings = field(default_factory=OscillationSettings)

    def __post_init__(self) -> None:
        for name in ("fmax_hz", "segment_s"):
            v = getattr(self, name)
            if not (v > 0.0 and math.isfinite(v)):
                raise ValueError(f"{name} must be > 0, got {v:g}")
        for name in ("settle_s", "transient_s"):
            v = getattr(self, name)
            if not (v >= 0.0 and math.isfinite(v)):
                raise ValueError(f"{name} must be >= 0, got {v:g}")
        k = self.stiffness_n_per_m
        if k is not None and not (k > 0.0 and math.isfinite(k)):
            raise ValueError(f"stiffness must be > 0 N/m, got {k:g}")


@dataclass
class Figures:
    """The analysis of one stretch of samples."""

    transparency: TransparencyResult | None
    energy: EnergyResult
    in_contact_pct: float | None
    oscillation: Oscillation | None
    problem: str | None  # why there is no transparency (too short, no motion, no stiffness)


def analyze_arrays(
    x: np.ndarray,
    force: np.ndarray,
    velocity: np.ndarray,
    fs_hz: float,
    stiffness_n_per_m: float | None,
    damping_n_s_per_m: float = 0.0,
    penetration: np.ndarray | None = None,
    fmax_hz: float = DEFAULT_FMAX_HZ,
    segment_s: float = DEFAULT_SEGMENT_S,
    oscillation_settings: OscillationSettings | None = None,
) -> Figures:
    """Transparency, energy, contact and vibration of motion x (m), hand force (N), v (m/s).

    ``penetration`` (m, > 0 in the wall) gives the contact share; the record should already
    leave out what is to be left out.
    """
    dt = 1.0 / fs_hz
    energy = passivity_observer(force, velocity, dt)
    touching = None if penetration is None else penetration > 0.0
    contact = None if touching is None else float(np.mean(touching) * 100.0)
    osc = oscillation(x, fs_hz, touching, oscillation_settings, segment_s)
    tr, problem = None, None
    if stiffness_n_per_m is None:
        problem = "no wall stiffness recorded (pass --stiffness)"
    elif stiffness_n_per_m <= 0.0:
        problem = "the wall stiffness is 0 (no wall): transparency is undefined"
    else:
        try:
            tr = transparency(
                x, force, fs_hz, stiffness_n_per_m, damping_n_s_per_m, fmax_hz, segment_s
            )
        except ValueError as exc:  # too short for the spectral settings, or no motion
            problem = str(exc)
    return Figures(tr, energy, contact, osc, problem)


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


def skip_samples(seg_size: int, skip_s: float, fs_hz: float) -> int:
    """Samples left out at a segment's start: ``skip_s``, at most a quarter of the segment."""
    return min(round(skip_s * fs_hz), seg_size // 4)


def _wall(seg: Segment, axis: int) -> tuple[float | None, float, float | None, float | None]:
    """(stiffness, damping, wall position along the axis, normal component along the axis)."""
    k = seg.value("environment_node", "stiffness_n_per_m")
    b = seg.value("environment_node", "damping_n_s_per_m")
    pos = seg.value("environment_node", "position")
    nrm = seg.value("environment_node", "normal")
    p_axis = float(pos[axis]) if isinstance(pos, list) and len(pos) == 3 else None
    n_axis = None
    if isinstance(nrm, list) and len(nrm) == 3:
        norm = math.sqrt(sum(float(c) ** 2 for c in nrm))
        n_axis = float(nrm[axis]) / norm if norm > 0 else None
    return (None if k is None else float(k)), float(b or 0.0), p_axis, n_axis


def analyze_bag(
    path: str | Path, selection: Selection | None = None, settings: AnalysisSettings | None = None
) -> BagAnalysis:
    """Read, segment and analyse one bag; ``BagError`` when no segment can be analysed."""
    sel = selection or Selection()
    st = settings or AnalysisSettings()
    data = read_bag(path, sel)
    rec = build_record(data)
    initial, changes = parameter_history(data.events, data.namespace)
    segments = split(rec.recv_ns, initial, changes, rec.t0_ns, rec.dt_ns)
    for series in (data.motion, data.force, data.velocity):  # the record holds what is needed
        if series is not None:
            series.stamps_ns = series.recv_ns = series.values = np.zeros(0)
    fs = rec.fs_hz
    axis = AXES[sel.axis]
    results = []
    for seg in segments:
        skip = skip_samples(seg.size, st.settle_s if seg.index == 0 else st.transient_s, fs)
        window = slice(seg.start + skip, seg.stop)
        k_rec, b, p_axis, n_axis = _wall(seg, axis)
        k: float | None
        if st.stiffness_n_per_m is not None:
            k, source = st.stiffness_n_per_m, "--stiffness"
        else:
            k, source = k_rec, ("recorded" if k_rec is not None else "unknown")
        x = rec.x[window]
        pen = None
        if p_axis is not None and n_axis:  # contact along the analysed axis
            pen = (x - p_axis) * n_axis
        figs = analyze_arrays(
            x,
            rec.force[window],
            rec.velocity[window],
            fs,
            k,
            b,
            pen,
            st.fmax_hz,
            st.segment_s,
            st.oscillation,
        )
        pulse = _pulse_response(seg, rec, k, p_axis, n_axis, fs)
        results.append(
            SegmentResult(
                bag=data.path,
                segment=seg,
                start_s=float(rec.time_s(seg.start)),
                end_s=float(rec.time_s(seg.stop)),
                analysed_from_s=float(rec.time_s(window.start)),
                analysed_s=(seg.stop - window.start) / fs,
                stiffness_n_per_m=k,
                stiffness_source=source,
                damping_n_s_per_m=b,
                figures=figs,
                record=rec,
                window=window,
                perturbation=pulse,
            )
        )
    if all(r.figures.transparency is None for r in results):
        r = max(results, key=lambda r: r.analysed_s)
        left_out = r.analysed_from_s - r.start_s
        where = (
            f"segment {r.segment.index} ({r.label}, {r.analysed_s:.3g} s analysed)"
            if len(results) > 1
            else f"{r.analysed_s:.3g} s analysed after leaving out {left_out:.3g} s"
        )
        coordinate = (
            f"{data.motion.topic} {sel.axis}"
            if data.motion.msgtype != JOINT_STATE
            else f"{data.motion.topic} joint {sel.joint or '(first)'}"
        )
        raise BagError(f"{data.path}: {_problem_text(r, coordinate)} ({where})")
    return BagAnalysis(
        data.path,
        data.storage,
        data.motion.topic,
        data.force.topic,
        rec.velocity_source,
        results,
    )


def _pulse_response(
    seg: Segment,
    rec: Record,
    k: float | None,
    p_axis: float | None,
    n_axis: float | None,
    fs: float,
) -> PerturbationResponse | None:
    """The onset protocol's answer to its force pulse, for a push-and-hold session segment.

    The recorded device parameters say whether the hand pushed and held with a pulse; the push
    comes from the reference offset through the grip and wall compliances (as the protocol set
    it), and the penetration from the recorded motion (the whole segment, no settling left out).
    """
    dev = seg.params.get("device_node", {})
    if dev.get("hand.behaviour") != "push_hold" or not dev.get("hand.perturbation_n"):
        return None
    if not k or p_axis is None or not n_axis or seg.index != 0:
        return None
    k_h = float(dev.get("hand.stiffness_n_per_m") or 0.0)
    if k_h <= 0.0:
        return None
    push = float(dev["hand.offset_m"]) / (1.0 / k + 1.0 / k_h)
    depth = (rec.x[seg.start : seg.stop] - p_axis) * n_axis
    start_s = float(rec.time_s(seg.start))
    try:
        return perturbation_response(
            depth,
            fs,
            float(dev.get("hand.perturbation_at_s", 0.0)) - start_s,
            float(dev.get("hand.perturbation_s", 0.0)),
            push / k,
        )
    except ValueError:
        return None


def _problem_text(r: SegmentResult, coordinate: str) -> str:
    p = r.figures.problem or "no transparency"
    if p.startswith("no motion"):
        return f"no motion: {coordinate} is constant"
    if p.startswith("record too short"):
        return "segment too short for the spectral settings: " + p.removeprefix(
            "record too short for the spectral settings: "
        )
    return p
