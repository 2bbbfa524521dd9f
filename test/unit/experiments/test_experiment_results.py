"""The experiments' typed results: ``results.json`` and the batch caches round-trip through the
dataclasses, a file of another format fails with one line, and the table of experiments drives
the report (one section per part run, in the table's order, with the figures the table names).
"""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from haptic_dob.identification.one_dof import SlideFit
from haptic_sim.experiments import (
    dob_mechanism,
    identification,
    observer_vs_sensor,
    report,
    results,
    slave_model,
    spread,
    sweeps,
)
from haptic_sim.experiments.entry import BatchJob
from haptic_sim.experiments.jsonio import from_json, to_json
from haptic_sim.experiments.parts import (
    EXPERIMENTS,
    PARTS,
    QUICK_PARTS,
    load_results,
    save_results,
)
from haptic_sim.experiments.phantom import PhantomResult, PhantomWallCell
from haptic_sim.experiments.records import Cell, Check, ExperimentResults, RunAnalysis
from haptic_sim.experiments.stability_map import MapPoint, StabilityMap
from haptic_sim.slide.session import SessionConfig

BASE = SessionConfig()


def _run(part: str, mode: str, kf: float, wall: float, **figures: object) -> RunAnalysis:
    return RunAnalysis(part, mode, kf, wall, f"{part}_{mode}_{wall:g}", 1, "bag", **figures)


def _every_part() -> dict[str, object]:
    """A small result of every part, as the runs would give them."""
    ch7 = [
        _run("ch7", m, kf, w, bandwidth_hz=1.0 + w / 1000.0, impedance_error_pct=20.0)
        for m, kf in (("OL", 0.0), ("CL", 2.0))
        for w in (80.0, 800.0)
    ]
    ch6 = [
        _run("ch6", "OL", 0.0, 2400.0, perturbation_growth_per_s=-0.1, perturbation_vibrates=False),
        _run("ch6", "OL", 0.0, 2800.0, perturbation_growth_per_s=None, perturbation_vibrates=True),
    ]
    kick = [
        dob_mechanism.KickPoint(w, 7.0, 0.24, 1e-4 * w / 4000.0, 30.0) for w in dob_mechanism.WALLS
    ]
    fits = [
        SlideFit("least_squares", "slide", 0.42, 1.25, 0.245, 1e-3, 0.02, 4e-3, 900, 0.01),
        SlideFit("step", "slide", 0.41, 2.04, None, None, None, None, 3500, None),
    ]
    return {
        "ch4": identification.Ch4Result(
            fits,
            [
                identification.Prediction(
                    identification.run_name(e), e.label(), f.method, 0.1, -0.05, [0.0, 1.5]
                )
                for e in (identification.IDENTIFY, *identification.VERIFY)
                for f in fits
            ],
            {
                identification.run_name(e): [0.0, 1.4]
                for e in (identification.IDENTIFY, *identification.VERIFY)
            },
            identification.ch4_checks(fits, BASE.device),
            [],
        ),
        "ch5": observer_vs_sensor.Ch5Result(
            [
                observer_vs_sensor.ObserverRun(
                    "ch5_free", 0.0, 0.05, 0.06, 0.01, 0.0, [0.1], [0.1], [0.1]
                )
            ]
        ),
        "ch7": results.ch7_result(ch7),
        "ch6": results.ch6_result(ch6, BASE),
        "map": StabilityMap(
            [
                MapPoint("OL", 0.0, 0.0, 41.6, 2538.0, False, 2544.0),
                MapPoint("CL", 2.0, 0.0, 41.6, None, False, 848.0),
                MapPoint("DOB", 100.0, 0.0, 41.6, 5.0, True, 25.2),
            ]
        ),
        "dob": dob_mechanism.DobStudy(
            kick,
            [
                dob_mechanism.FirstVibrating(
                    7.0, 0.24, dob_mechanism.first_vibrating(kick, 7.0, 0.24)
                )
            ],
            [dob_mechanism.LinearOnset(100.0, 7.0, 0.0, None)],
            [
                dob_mechanism.ChatterGain(100.0, 7.7, 8.4),
                dob_mechanism.ChatterGain(1.0, 1322.0, None),
            ],
            [
                dob_mechanism.MismatchCell(800.0, 25.0, m, 3.0, 30.0)
                for m in ("assumed", "no Coulomb")
            ],
            [dob_mechanism.GripPoint("bench hand", 3200.0, 0.0, 1.0)],
        ),
        "sweeps": sweeps.SweepStudy(
            [
                sweeps.SweepCell("grip", "OL", 0.0, 2400.0, 10.0, 6.04, 25.0, 0.85, -1.6, -1.6, 0),
                sweeps.SweepCell("force_limit", "CL", 2.0, 80.0, 4.0, *[None] * 5, 21.0),
                sweeps.SweepCell(
                    "sensor", "CL", 2.0, 1600.0, 5.0, 7.5, 12.0, 0.98, -0.1, -0.5, 0.0, 588.0
                ),
            ],
            [spread.SeedCell(1, "OL", 0.0, 800.0, 4.07), spread.SeedCell(1, "CL", 2.0, 80.0, None)],
        ),
        "phantom": PhantomResult(
            [0.0, 0.012, 0.004], [0.0, 0.95, 0.49], [PhantomWallCell(1.0, 0.3, 8e-5, 0.008)]
        ),
        "slave": slave_model.SlaveModelResult(
            60.0,
            1676,
            8.05,
            "runs/slave_excitation/identified.urdf",
            ["joint1"],
            [0.06],
            [9.9],
            [0.12],
            [0.45],
            [1.32],
            [0.116],
            [0.446],
            [1.324],
            ["link1"],
            [4.0],
            [4.0],
            ["link1.m"],
            [
                slave_model.ModelRow("CAD", 6.1, 5.0, 32.6, [1.7, 2.2]),
                slave_model.ModelRow("identified", 0.027, 0.009, 0.07, [0.006, 0.015]),
            ],
            [Check("held-out residual", True)],
            [],
        ),
    }


def _results(parts: dict[str, object]) -> ExperimentResults:
    params = {"device_node": {"seed": 0}}
    return ExperimentResults("slide_sim", params, False, 0, list(parts), parts, {"total": 1.0})


def test_results_json_round_trips_through_the_dataclasses(tmp_path: Path) -> None:
    res = _results(_every_part())
    save_results(tmp_path / "results.json", res)
    assert load_results(tmp_path / "results.json") == res
    # readable: indented, named fields, nulls, the parts under their names
    text = (tmp_path / "results.json").read_text()
    data = json.loads(text)
    assert list(data["results"]) == list(PARTS)
    assert data["results"]["ch7"]["rows"][0]["bandwidth_hz"] == 1.08
    assert data["results"]["ch4"]["fits"][1]["coulomb_n"] is None
    assert data["results"]["ch6"]["onsets"][0]["points"][1]["growth_per_s"] is None
    assert data["results"]["dob"]["kick"][-1]["vibrates"] is True  # derived, for the reader
    assert '\n  "ch7": {\n' in text
    # the report from the file is the report from the run
    report.write(tmp_path / "a", res, BASE)
    report.write(tmp_path / "b", load_results(tmp_path / "results.json"), BASE)
    assert (tmp_path / "a" / "report.md").read_text() == (tmp_path / "b" / "report.md").read_text()


@pytest.mark.parametrize("part", [e.part for e in EXPERIMENTS if isinstance(e.job, BatchJob)])
def test_batch_caches_round_trip(part: str) -> None:
    (e,) = (e for e in EXPERIMENTS if e.part == part)
    value = _every_part()[part]
    assert from_json(e.result_type, json.loads(json.dumps(to_json(value)))) == value


def test_a_cache_of_another_format_is_one_error_line(tmp_path: Path) -> None:
    from haptic_dob.errors import InputError
    from haptic_sim.cli.experiment import _cached

    path = tmp_path / "batch" / "map.json"
    value = _every_part()["map"]
    calls = []

    def compute() -> object:
        calls.append(1)
        return value

    assert _cached(path, StabilityMap, compute) == value
    assert _cached(path, StabilityMap, compute) == value
    assert calls == [1]  # the second time, from the file
    path.write_text(json.dumps([{"controller": "OL"}]))  # the old format: a bare list
    with pytest.raises(InputError, match=r"map\.json: StabilityMap: expected a JSON object"):
        _cached(path, StabilityMap, lambda: value)


@pytest.mark.parametrize(
    ("data", "message"),
    [
        ({"wall": 1.0, "growth_per_s": None}, "missing 1 required positional argument"),
        ({"wall": 1.0, "growth_per_s": None, "vibrates": True, "x": 1}, "unknown field"),
        (
            {"wall": "1", "growth_per_s": None, "vibrates": True},
            "OnsetPoint.wall: expected a number",
        ),
        ({"wall": 1.0, "growth_per_s": None, "vibrates": 1}, "OnsetPoint.vibrates: expected bool"),
    ],
)
def test_from_json_names_what_does_not_fit(data: dict[str, object], message: str) -> None:
    from haptic_sim.experiments.records import OnsetPoint

    with pytest.raises(ValueError, match=message):
        from_json(OnsetPoint, data)


def test_a_run_analysis_takes_haptic_analyze_figures_by_name() -> None:
    segment = {"bag": "b", "kf": 2.0, "bandwidth_hz": 5.5, "segment": 0, "parameters": {}}
    row = RunAnalysis.from_segment(Cell("ch7", "CL", 2.0, 800.0), "r", 3, segment)
    assert (row.part, row.mode, row.kf, row.wall, row.name, row.segments) == (
        "ch7",
        "CL",
        2.0,
        800.0,
        "r",
        3,
    )
    assert row.bag == "b" and row.bandwidth_hz == 5.5 and row.problem is None
    assert row.where == "CL Kf=2 at 800 N/m"


def test_the_table_names_each_part_and_figure_once() -> None:
    assert len(set(PARTS)) == len(PARTS) == 9 and QUICK_PARTS == ["ch7"]
    files = [f.file for e in EXPERIMENTS for f in e.figures]
    assert len(set(files)) == len(files)


def test_the_report_has_a_section_per_part_run_in_the_tables_order(tmp_path: Path) -> None:
    every = _every_part()
    chosen = {p: every[p] for p in ("phantom", "map", "ch7")}  # asked for in another order
    text = report.write(tmp_path, _results(chosen), BASE).read_text()
    headings = [line for line in text.splitlines() if line.startswith("## ")]
    expected = [f"## {e.heading}" for e in EXPERIMENTS if e.part in chosen]
    assert headings[0] == "## One plant and one observer configuration"  # stated once, first
    assert headings[1 : len(expected) + 1] == expected
    for e in EXPERIMENTS:
        for f in e.figures:
            assert (f"![{f.alt}](figures/{f.file})" in text) == (e.part in chosen)
            drawn = (tmp_path / "figures" / f.file).is_file()
            assert drawn == (e.part in chosen and f.plot is not None), f.file
    assert "parts: phantom, map, ch7" in text
    summary = report.console_summary(_results(chosen))
    assert summary.splitlines()[0].startswith("controller") and "FAIL: CL Kf=2" in summary
