"""Per-segment transparency, vibration and energy of a recorded session: ``analyze_bag``.

``analyze_bag`` reads a bag, resamples it onto one grid (``haptic_dob.bag.resample``), labels its
segments with the recorded parameters (``haptic_dob.bag.segments``) and analyses each with
``haptic_dob.analysis.analyze_arrays`` (the same function an in-process check calls on arrays).

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

import numpy as np

from haptic_dob.analysis.figures import analyze_arrays
from haptic_dob.analysis.oscillation import OscillationSettings
from haptic_dob.analysis.transparency import DEFAULT_FMAX_HZ
from haptic_dob.analysis.vibration import PerturbationResponse, perturbation_response
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.reader import AXES, Selection, read_bag
from haptic_dob.bag.resample import Record, build_record
from haptic_dob.bag.results import BagAnalysis, SegmentResult
from haptic_dob.bag.segments import Segment, parameter_history, split
from haptic_dob.bag.series import JOINT_STATE


@dataclass(frozen=True)
class AnalysisSettings:
    """What to leave out and the spectral settings (s, Hz)."""

    fmax_hz: float = DEFAULT_FMAX_HZ
    settle_s: float = 2.0
    transient_s: float = 0.5
    segment_s: float | None = None  # None: the transparency's default for the segment's length
    stiffness_n_per_m: float | None = None  # overrides the recorded wall stiffness
    oscillation: OscillationSettings = field(default_factory=OscillationSettings)

    def __post_init__(self) -> None:
        for name in ("fmax_hz", "segment_s"):
            v = getattr(self, name)
            if v is not None and not (v > 0.0 and math.isfinite(v)):
                raise ValueError(f"{name} must be > 0, got {v:g}")
        for name in ("settle_s", "transient_s"):
            v = getattr(self, name)
            if not (v >= 0.0 and math.isfinite(v)):
                raise ValueError(f"{name} must be >= 0, got {v:g}")
        k = self.stiffness_n_per_m
        if k is not None and not (k > 0.0 and math.isfinite(k)):
            raise ValueError(f"stiffness must be > 0 N/m, got {k:g}")


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
