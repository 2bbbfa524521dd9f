"""Output of ``haptic-analyze``: a readable table, JSON, CSV, and the thesis-shaped summary.

The summary of several bags has the shape of the thesis's Tables 7.1 and 7.2: one row per
controller (``OL``, ``CL Kf=2``, ``DOB Kf=1``...), one column per wall stiffness, bandwidth (Hz)
in the first table and average normalized impedance error inside the band (%) in the second.
A cell measured more than once shows the mean.
"""

from __future__ import annotations

import csv
import io
import json
import math
from collections.abc import Sequence
from typing import Any

from haptic_dob.bag.results import BagAnalysis, SegmentResult

CSV_FIELDS = (
    "bag",
    "segment",
    "controller",
    "kf",
    "stiffness_n_per_m",
    "stiffness_source",
    "damping_n_s_per_m",
    "observer_gain",
    "observer_output_limit",
    "start_s",
    "end_s",
    "duration_s",
    "analysed_from_s",
    "analysed_s",
    "bandwidth_hz",
    "band_limited_by_fmax",
    "band_below_first_bin",
    "impedance_error_pct",
    "coherence_in_band",
    "in_contact_pct",
    "vibrating",
    "vibration_amplitude_m",
    "vibration_frequency_hz",
    "vibration_growth_per_s",
    "vibration_peak_fraction",
    "vibrating_s",
    "max_active_energy_j",
    "max_active_at_s",
    "final_energy_j",
    "missing_samples",
    "sample_rate_hz",
    "problem",
)


def _fmt(v: Any, spec: str, unit: str = "") -> str:
    if v is None or (isinstance(v, float) and not math.isfinite(v)):
        return "-"
    return f"{v:{spec}}{unit}"


def table(analyses: Sequence[BagAnalysis]) -> str:
    """One block per bag: a line per segment with its label and headline figures."""
    lines = []
    head = (
        f"{'seg':>3}  {'time (s)':>15}  {'controller':<12} {'K (N/m)':>8}  {'bandwidth':>9}  "
        f"{'imp. error':>10}  {'coherence':>9}  {'contact':>7}  {'vibration':<22}  "
        f"{'max active':>10}"
    )
    for a in analyses:
        lines.append(
            f"{a.path}: {a.storage}, motion {a.motion_topic}, force {a.force_topic}, "
            f"velocity {a.velocity_source}, {len(a.segments)} segment(s)"
        )
        lines.append(head)
        for r in a.segments:
            lines.append(_row(r))
            if r.figures.problem and r.figures.transparency is None:
                lines.append(f"     segment {r.segment.index}: {r.figures.problem}")
        missing = a.segments[0].record.missing if a.segments else 0
        if missing:
            lines.append(f"     {missing} missing sample(s) interpolated")
        lines.append("")
    return "\n".join(lines).rstrip("\n")


def _row(r: SegmentResult) -> str:
    d = r.as_dict()
    c = r.controller
    ctl = c if c in ("OL", "?") or r.kf is None else f"{c} Kf={r.kf:g}"
    if d["vibrating"] is None:
        vib = "-"
    elif d["vibrating"]:
        vib = (
            f"YES {d['vibration_amplitude_m'] * 1e3:.3f} mm "
            f"{_fmt(d['vibration_frequency_hz'], '.1f')} Hz"
        )
    else:
        vib = f"no ({d['vibration_amplitude_m'] * 1e3:.3f} mm)"
    bw = _fmt(d["bandwidth_hz"], ".2f", " Hz")
    if d["band_limited_by_fmax"]:
        bw = ">=" + bw
    elif d["band_below_first_bin"]:
        bw = "<" + bw
    return (
        f"{r.segment.index:>3}  {r.start_s:>7.2f}-{r.end_s:<7.2f}  {ctl:<12} "
        f"{_fmt(r.stiffness_n_per_m, '.0f'):>8}  {bw:>9}  "
        f"{_fmt(d['impedance_error_pct'], '.1f', ' %'):>10}  "
        f"{_fmt(d['coherence_in_band'], '.3f'):>9}  {_fmt(d['in_contact_pct'], '.0f', ' %'):>7}  "
        f"{vib:<22}  {_fmt(d['max_active_energy_j'] * 1e3, '.3f', ' mJ'):>10}"
    )


def as_json(analyses: Sequence[BagAnalysis]) -> str:
    """A JSON array: one object per segment of every bag."""
    return json.dumps([r.as_dict() for a in analyses for r in a.segments], indent=2)


def as_csv(analyses: Sequence[BagAnalysis]) -> str:
    """CSV with a header row and one row per segment (``CSV_FIELDS``)."""
    out = io.StringIO()
    w = csv.DictWriter(out, fieldnames=CSV_FIELDS, extrasaction="ignore", lineterminator="\n")
    w.writeheader()
    for a in analyses:
        for r in a.segments:
            w.writerow({k: "" if v is None else v for k, v in r.as_dict().items()})
    return out.getvalue()


def controller_label(r: SegmentResult) -> str:
    """Row label of the summary tables: ``OL``, ``CL Kf=2``, ``DOB Kf=1`` or ``?``."""
    c = r.controller
    return c if c in ("OL", "?") or r.kf is None else f"{c} Kf={r.kf:g}"


def summary(analyses: Sequence[BagAnalysis]) -> str:
    """Tables 7.1 (bandwidth, Hz) and 7.2 (impedance error, %): controllers by stiffness."""
    cells: dict[tuple[str, float], list[tuple[float, float]]] = {}
    for a in analyses:
        for r in a.segments:
            tr = r.figures.transparency
            if tr is None or r.stiffness_n_per_m is None:
                continue
            key = (controller_label(r), r.stiffness_n_per_m)
            cells.setdefault(key, []).append((tr.bandwidth_hz, tr.impedance_error_pct))
    if not cells:
        return "no segment has transparency figures"
    order = {"OL": 0, "CL": 1, "DOB": 2}
    rows = sorted({k[0] for k in cells}, key=lambda c: (order.get(c.split()[0], 3), c))
    cols = sorted({k[1] for k in cells})
    out = []
    for title, j, spec in (
        ("bandwidth (Hz)", 0, ".2f"),
        ("average normalized impedance error inside the band (%)", 1, ".1f"),
    ):
        out.append(f"{title}, controllers by wall stiffness:")
        out.append(f"{'controller':<14}" + "".join(f"{k:>10g} N/m" for k in cols))
        for c in rows:
            line = f"{c:<14}"
            for k in cols:
                vals = [v[j] for v in cells.get((c, k), []) if math.isfinite(v[j])]
                cell = f"{sum(vals) / len(vals):{spec}}" if vals else "-"
                line += f"{cell:>14}"
            out.append(line)
        out.append("")
    return "\n".join(out).rstrip("\n")
