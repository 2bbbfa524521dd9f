"""From recorded runs to numbers: each bag analysed as ``haptic-analyze`` does, then tabulated.

``analyse_run`` writes ``analysis.json`` beside the run's bag with exactly what
``haptic-analyze BAG --json`` prints for it (default settings), so every number of the report can
be regenerated from the bags by the analysis alone. The chapter-7 tables take the transparency of
each run; the chapter-6 onsets take each run's pulse response (``perturbation_growth_per_s``) and
interpolate its zero crossing along the walls (``haptic_sim.stability.onset``), as the batch sweep
does.
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any

from haptic_sim.experiments.graph_runs import GraphRun, bag_path, run_dir
from haptic_sim.experiments.plan import THESIS_BANDWIDTH, THESIS_ERROR, label
from haptic_sim.stability import StabilityPoint, onset


def analyse_run(root: Path, run: GraphRun) -> dict[str, Any]:
    """Analyse a complete run's bag (cached in ``analysis.json``); its longest segment's figures."""
    out = run_dir(root, run) / "analysis.json"
    bag = bag_path(root, run)
    if out.is_file() and out.stat().st_mtime >= bag.stat().st_mtime:
        segments = json.loads(out.read_text(encoding="utf-8"))
    else:
        from haptic_dob.bag.analyze import analyze_bag
        from haptic_dob.bag.report import as_json

        text = as_json([analyze_bag(bag)])
        out.write_text(text + "\n", encoding="utf-8")
        segments = json.loads(text)
    seg = max(segments, key=lambda s: s["duration_s"])
    return {**run.meta, "name": run.name, "segments": len(segments), **_figures(seg)}


def _figures(seg: dict[str, Any]) -> dict[str, Any]:
    keys = (
        "bag",
        "controller",
        "kf",
        "stiffness_n_per_m",
        "bandwidth_hz",
        "band_limited_by_fmax",
        "impedance_error_pct",
        "coherence_in_band",
        "in_contact_pct",
        "vibrating",
        "vibration_amplitude_m",
        "vibration_frequency_hz",
        "max_active_energy_j",
        "perturbation_growth_per_s",
        "perturbation_vibrates",
        "observer_gain",
        "duration_s",
        "problem",
    )
    return {k: seg.get(k) for k in keys}


def ch7_checks(rows: list[dict[str, Any]]) -> list[tuple[str, bool]]:
    """The issue's acceptance checks on the chapter-7 cells that were run."""
    bw = {(r["mode"], r["kf"], r["wall"]): r["bandwidth_hz"] for r in rows}
    checks = []
    thesis_ol = dict(zip([80.0, 800.0, 1600.0, 2400.0], THESIS_BANDWIDTH[("OL", 0.0)], strict=True))
    for wall in (80.0, 800.0, 1600.0):
        got = bw.get(("OL", 0.0, wall))
        if got is not None:
            ref = thesis_ol[wall]
            checks.append(
                (
                    f"OL bandwidth at {wall:g} N/m {got:.2f} Hz within +-15 % of the thesis's "
                    f"{ref:g} Hz",
                    abs(got - ref) <= 0.15 * ref,
                )
            )
    for mode, kf in (("CL", 2.0), ("DOB", 1.0)):
        for wall in (800.0, 1600.0):
            got, ol = bw.get((mode, kf, wall)), bw.get(("OL", 0.0, wall))
            if got is not None and ol is not None:
                checks.append(
                    (
                        f"{label(mode, kf)} bandwidth at {wall:g} N/m ({got:.2f} Hz) exceeds "
                        f"OL ({ol:.2f} Hz)",
                        got > ol,
                    )
                )
    return checks


def ch6_onsets(rows: list[dict[str, Any]]) -> dict[str, dict[str, Any]]:
    """Per controller: the points (wall, growth) and the interpolated onset (N/m)."""
    out: dict[str, dict[str, Any]] = {}
    for r in sorted(rows, key=lambda r: r["wall"]):
        ctl = label(r["mode"], r["kf"])
        entry = out.setdefault(ctl, {"mode": r["mode"], "kf": r["kf"], "points": []})
        g = r["perturbation_growth_per_s"]
        entry["points"].append(
            StabilityPoint(
                r["wall"],
                math.nan if g is None else g,
                r.get("vibration_frequency_hz") or math.nan,
                r.get("vibration_amplitude_m") or math.nan,
                bool(r["perturbation_vibrates"]) and g is None,
            )
        )
    for entry in out.values():
        entry["onset_n_per_m"] = onset(entry["points"])
        entry["first_point_vibrates"] = entry["points"][0].vibrates
        entry["points"] = [
            {
                "wall": p.stiffness_n_per_m,
                "growth_per_s": None if math.isnan(p.growth_per_s) else p.growth_per_s,
                "vibrates": p.vibrates,
            }
            for p in entry["points"]
        ]
    return out


def bound(mode: str, kf: float, b: float, rate_hz: float) -> float:
    """``2 b / (T (1 + Kf))`` (N/m), Kf = 0 for OL."""
    return 2.0 * b * rate_hz / (1.0 + (0.0 if mode == "OL" else kf))


def thesis_cell(mode: str, kf: float, wall: float) -> tuple[float | None, float | None]:
    """The thesis's (bandwidth Hz, impedance error %) of a chapter-7 cell, None if not there."""
    walls = [80.0, 800.0, 1600.0, 2400.0]
    if (mode, kf) not in THESIS_BANDWIDTH or wall not in walls:
        return None, None
    i = walls.index(wall)
    return THESIS_BANDWIDTH[(mode, kf)][i], THESIS_ERROR[(mode, kf)][i]


def ch6_checks(
    onsets: dict[str, dict[str, Any]], b: float, rate_hz: float
) -> list[tuple[str, bool]]:
    """The issue's checks: OL and CL onsets through the graph within +-5 % of the bound."""
    checks = []
    for ctl, e in onsets.items():
        k_on = e["onset_n_per_m"]
        if e["mode"] not in ("OL", "CL"):
            continue
        bnd = bound(e["mode"], e["kf"], b, rate_hz)
        ok = k_on is not None and not e["first_point_vibrates"] and abs(k_on - bnd) <= 0.05 * bnd
        got = "none" if k_on is None else f"{k_on:.0f} N/m"
        checks.append((f"{ctl} onset through the graph {got} within +-5 % of {bnd:.0f} N/m", ok))
    return checks
