"""``haptic-experiment``: the quick reproduction through the node graph, its report, and its parts.

The quick variant (the demo) records OL, CL Kf=2 and DOB Kf=1 at 800 N/m through the node graph;
``haptic-analyze`` on its bags must give the report's numbers, and a second run resumes from the
bags. The rest checks the pieces on their own: the onset interpolation from graph results, the
acceptance checks, the report's rendering, and the DOB mechanism the report explains.
"""

from __future__ import annotations

import json
import signal
import subprocess
import time
from pathlib import Path

import pytest

from conftest import tool
from haptic_dob.runtime.params import load_node_params
from haptic_sim.experiments import dob, results
from haptic_sim.experiments.parts import CH7, load_results
from haptic_sim.experiments.plan import chapter6_plan, chapter6_runs, chapter7_runs
from haptic_sim.experiments.records import Cell, ExperimentResults, RunAnalysis
from haptic_sim.session import SessionConfig
from haptic_sim.stability import law_for

CONFIG = Path(__file__).resolve().parents[1] / "config" / "slide_sim.yaml"


@pytest.mark.slow
@pytest.mark.multiprocess
def test_quick_experiment_runs_through_the_graph_resumes_and_haptic_analyze_reproduces_it(
    tmp_path,
) -> None:
    out = tmp_path / "report"
    argv = [tool("haptic-experiment"), "--quick", "--out", str(out)]
    # Ctrl-C once the first run is recorded: every launch stops, the complete bag stays
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        # a test run in the background inherits SIGINT ignored; Ctrl-C reaches a foreground tool
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    seen = []
    try:
        deadline = time.monotonic() + 180
        for line in proc.stdout:
            seen.append(line)
            if line.startswith("[  1/3]") or time.monotonic() > deadline:
                break
        assert seen and seen[-1].startswith("[  1/3]"), "".join(seen)  # progress as it runs
        proc.send_signal(signal.SIGINT)
        assert proc.wait(60) == 130, "".join(seen) + proc.stdout.read()
        seen += proc.stdout.readlines()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    left = subprocess.run(["pgrep", "-f", str(out)], capture_output=True, text=True)
    assert left.stdout.strip() == "", "launches still running after Ctrl-C"
    # the next run resumes from the recorded bag
    p = subprocess.run(argv, capture_output=True, text=True, timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr
    # exactly the runs reported finished before the interrupt count as recorded (a run stopped
    # half-way is neither reported nor kept)
    finished = sum(line.startswith("[  ") for line in seen)
    assert f"{finished} of 3 runs already recorded (resuming)" in p.stdout, "".join(seen) + p.stdout
    ch7 = CH7.result_in(load_results(out / "results.json"))
    assert ch7 is not None
    assert {(r.mode, r.kf, r.wall) for r in ch7.rows} == {
        ("OL", 0.0, 800.0),
        ("CL", 2.0, 800.0),
        ("DOB", 1.0, 800.0),
    }
    report = (out / "report.md").read_text()
    assert "| OL |" in report and "Table 7.1" in report
    assert (out / "figures" / "ch7_transparency.png").stat().st_size > 10_000
    # every number comes from the bag: haptic-analyze on it prints the same figures
    for row in ch7.rows:
        assert row.segments == 1 and row.problem is None
        assert row.duration_s is not None and row.duration_s > 19.9  # the whole 20 s session
        a = subprocess.run(
            [tool("haptic-analyze"), row.bag, "--json"],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert a.returncode == 0, a.stderr
        (seg,) = json.loads(a.stdout)
        assert seg["controller"] == row.mode and seg["kf"] == row.kf
        assert seg["stiffness_n_per_m"] == row.wall
        assert seg["bandwidth_hz"] == row.bandwidth_hz
        assert seg["impedance_error_pct"] == row.impedance_error_pct
    # the thesis's ordering at 800 N/m: force feedback widens the band
    bw = {r.mode: r.bandwidth_hz for r in ch7.rows}
    assert bw["CL"] > bw["OL"] and bw["DOB"] > bw["OL"]
    # once everything is recorded, nothing runs again
    again = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "3 of 3 runs already recorded" in again.stdout
    assert "node-graph runs" in again.stdout and "simulated in" not in again.stdout
    assert CH7.result_in(load_results(out / "results.json")) == ch7


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--parts", "ch7,nope"], "--parts takes a comma-separated subset"),
        (["--workers", "0"], "--workers must be >= 1"),
        (["--config", "no_such_config"], "no config 'no_such_config'"),
    ],
)
def test_bad_arguments_get_one_error_line(tmp_path, args, message) -> None:
    p = subprocess.run(
        [tool("haptic-experiment"), "--out", str(tmp_path / "r"), *args],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode == 2
    assert message in p.stderr and "Traceback" not in p.stderr
    assert not (tmp_path / "r" / "runs").exists()


def test_fresh_refuses_a_directory_that_is_not_an_experiment(tmp_path) -> None:
    victim = tmp_path / "precious"
    victim.mkdir()
    (victim / "thesis.tex").write_text("keep me")
    p = subprocess.run(
        [tool("haptic-experiment"), "--quick", "--fresh", "--out", str(victim)],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert p.returncode == 2 and "does not look like an experiment directory" in p.stderr
    assert (victim / "thesis.tex").read_text() == "keep me"


def test_the_plan_holds_the_thesis_cells(root) -> None:
    config = root / "config" / "slide_sim.yaml"
    ch7 = chapter7_runs(config)
    assert len(ch7) == 16 and {r.duration_s for r in ch7} == {40.0}
    assert len({r.name for r in ch7}) == 16
    for r in ch7:  # OL and CL leave the observer out; DOB waits for it
        has_observer = "observer_node" in r.params
        assert has_observer == (r.cell.mode == "DOB")
        assert ("observer_node" in r.params["device_node"]["wait_for"]) == has_observer
    ch6 = chapter6_runs(config)
    walls = {m: sorted(r.cell.wall for r in ch6 if r.cell.mode == m) for m in ["OL", "CL"]}
    # the walls bracket the bounds 2544 (OL) and 848 (CL Kf=2) N/m
    assert any(w < 2544 for w in walls["OL"]) and any(w > 2544 for w in walls["OL"])
    assert any(w < 848 for w in walls["CL"]) and any(w > 848 for w in walls["CL"])
    assert all(r.params["/**"]["slide.coulomb_n"] == 0.0 for r in ch6)
    assert all(r.params["device_node"]["plant.coulomb_n"] == 0.0 for r in ch6)
    # the tap keeps the configuration's plant and model: no friction (or other plant) override
    tap = [r for r in chapter6_plan(config, 0, False) if r.cell.part == "ch6tap"]
    base = load_node_params(config)
    assert {r.cell.mode for r in tap} == {"OL", "CL", "DOB"}
    for r in tap:
        assert r.params["/**"] == base["/**"]
        dev = r.params["device_node"]
        assert {k: v for k, v in dev.items() if k.startswith("plant.")} == {
            k: v for k, v in base["device_node"].items() if k.startswith("plant.")
        }
        assert r.params["device_node"]["hand.perturbation_n"] == 3.0
    assert {r.cell.wall for r in tap if r.cell.mode == "DOB"} >= {800.0, 1600.0, 2400.0, 3200.0}


def test_chapter_4_runs_hold_the_slide_in_a_spring_and_add_the_thesiss_inputs(root) -> None:
    from haptic_sim.experiments import ch4

    runs = ch4.chapter4_runs(root / "config" / "slide_sim.yaml")
    assert [r.name for r in runs] == [
        "ch4_step_2p4",
        "ch4_step_1p6",
        "ch4_step_3p2",
        "ch4_sine_0p6",
    ]
    for r in runs:
        env = r.params["environment_node"]
        assert env["two_sided"] and env["stiffness_n_per_m"] == 80.0
        assert r.params["device_node"]["hand.behaviour"] == "none"
        assert r.params["controller_node"]["mode"] == "OL" and "observer_node" not in r.params
        assert "joint_states" in r.params["recorder_node"]["topics"]
    assert runs[-1].params["environment_node"]["excitation.frequency_hz"] == 2.0


def test_chapter_5_runs_record_the_estimate_the_sensor_and_the_true_force(root) -> None:
    from haptic_sim.experiments import ch5

    runs = ch5.chapter5_runs(root / "config" / "slide_sim.yaml")
    assert [r.name for r in runs] == ["ch5_free", "ch5_wall800"]
    for r in runs:
        assert {"wrench_estimate", "wrench_measured", "sim/hand_wrench"} <= set(
            r.params["recorder_node"]["topics"]
        )
        assert "observer_node" in r.params["device_node"]["wait_for"]
        assert r.params["controller_node"]["mode"] == "OL"
    assert runs[0].params["environment_node"]["stiffness_n_per_m"] == 0.0
    assert runs[0].params["device_node"]["hand.offset_m"] == 0.0


def test_chapter_4_checks_hold_least_squares_and_the_step_method_to_their_bounds() -> None:
    from dataclasses import replace

    from haptic_dob.identification import SlideFit
    from haptic_sim.experiments.ch4 import ch4_checks
    from haptic_sim.slide import SlideDeviceParams

    truth = SlideDeviceParams()  # m 0.416, c 1.272, Fc 0.24

    def fit(method: str, m: float, c: float, fc: float | None) -> SlideFit:
        return SlideFit(method, "slide", m, c, fc, None, None, None, 100, None)

    checks = ch4_checks(
        [fit("least_squares", 0.43, 1.31, 0.29), fit("step", 0.46, 1.44, 0.19)], truth
    )
    assert [c.passed for c in checks] == [
        True,
        True,
    ]  # m 3.4 %, c 3.0 %, Fc 20.8 %; 10.6, 13.2, 20.8
    assert "c 13.2 % (within 15 %)" in checks[1].text
    checks = ch4_checks(
        [fit("least_squares", 0.44, 1.27, 0.24), fit("step", 0.41, 2.0, None)], truth
    )
    assert [c.passed for c in checks] == [False, False] and "m 5.8 %" in checks[0].text
    assert "c 57.2 %" in checks[1].text
    checks = ch4_checks(
        [fit("thesis_step", 0.41, 2.0, None), fit("thesis_step", 0.48, 1.3, None)], truth
    )
    assert [c.passed for c in checks] == [True, False]  # m 1.4 %, 15.4 %; c not held
    assert "their c, 57 % off, takes the Coulomb friction in" in checks[0].text
    assert ch4_checks([fit("least_squares", 0.416, 1.272, 0.0)], replace(truth, coulomb_n=0.0))[
        0
    ].passed  # a frictionless truth: Fc compared absolutely


def _row(mode: str, kf: float, wall: float, growth: float | None, vib: bool) -> RunAnalysis:
    return RunAnalysis(
        "ch6",
        mode,
        kf,
        wall,
        f"ch6_{mode}_{wall:g}",
        1,
        "bag",
        perturbation_growth_per_s=growth,
        perturbation_vibrates=vib,
    )


def _ch7_row(mode: str, kf: float, wall: float, bandwidth_hz: float) -> RunAnalysis:
    name = f"ch7_{mode}_{wall:g}"
    return RunAnalysis("ch7", mode, kf, wall, name, 1, "bag", bandwidth_hz=bandwidth_hz)


def test_ch6_onset_is_the_interpolated_zero_crossing_of_the_growth_rate() -> None:
    rows = [
        _row("OL", 0.0, 2600.0, 0.2, True),
        _row("OL", 0.0, 2200.0, -0.1, False),
        _row("CL", 2.0, 800.0, None, True),  # already vibrating before the pulse
        _row("DOB", 100.0, 800.0, -0.5, False),
    ]
    onsets = results.ch6_onsets(rows)
    on = {e.controller: e for e in onsets}
    assert on["OL"].onset_n_per_m == pytest.approx(2200.0 + 400.0 / 3.0)
    assert [p.wall for p in on["OL"].points] == [2200.0, 2600.0]
    assert on["CL Kf=2"].onset_n_per_m == 800.0 and on["CL Kf=2"].first_point_vibrates
    assert on["DOB Kf=100"].onset_n_per_m is None
    checks = results.ch6_checks(onsets, SessionConfig())
    # OL 2333 vs the linear model's 2314 for the default plant (its 0.05 ms lag); CL below range
    assert {c.text.split(" onset")[0]: c.passed for c in checks} == {"OL": True, "CL Kf=2": False}


def test_ch7_checks_compare_with_the_thesis_and_with_ol() -> None:
    rows = [
        _ch7_row("OL", 0.0, 800.0, 4.5),  # 3.8 Hz +- 15 %: no
        _ch7_row("OL", 0.0, 1600.0, 5.0),
        _ch7_row("CL", 2.0, 800.0, 5.0),
        _ch7_row("DOB", 1.0, 800.0, 4.0),
    ]
    checks = results.ch7_checks(rows)
    assert [c.passed for c in checks] == [False, True, True, False]


def test_report_renders_every_section(tmp_path) -> None:
    from haptic_sim.experiments import report

    base = SessionConfig.from_yaml(CONFIG)
    ch7 = [
        RunAnalysis(
            "ch7",
            "OL",
            0.0,
            w,
            f"ch7_OL_{w:g}",
            1,
            "bag",
            bandwidth_hz=1.0 + w / 1000.0,
            impedance_error_pct=20.0,
            band_limited_by_fmax=False,
            vibrating=False,
        )
        for w in (80.0, 800.0)
    ]
    ch6 = [_row("OL", 0.0, 2200.0, -0.1, False), _row("OL", 0.0, 2600.0, 0.2, True)]
    kick = [
        dob.KickPoint(w, 7.0, 0.24, r, 25.0)
        for w, r in zip(dob.WALLS, [0, 0, 0, 3e-4, 4e-4, 4e-4, 4e-4], strict=True)
    ]
    study = dob.DobStudy(
        kick,
        [dob.FirstVibrating(7.0, 0.24, dob.first_vibrating(kick, 7.0, 0.24))],
        [dob.LinearOnset(100.0, 7.0, 1.0, 23.0)],
        [dob.ChatterGain(100.0, 7.7, 8.4)],
        [],
        [
            dob.GripPoint(g.name, 2400.0, 3e-4 if g is dob.GRIPS[0] else 0.0, 25.0)
            for g in dob.GRIPS
        ],
    )
    res = ExperimentResults(
        config="slide_sim",
        config_params={},
        quick=False,
        seed=0,
        parts=["ch7", "ch6", "dob"],
        results={
            "ch7": results.ch7_result(ch7),
            "ch6": results.ch6_result(ch6, base),
            "dob": study,
        },
        timing_s={"total": 1.0},
    )
    path = report.write(tmp_path, res, base)
    text = path.read_text()
    assert "| OL | 1.08 / 1.3 | 1.80 / 3.8 |" in text  # simulation beside thesis Table 7.1
    assert "| OL | 2333 | 2544 | 2400 |" in text
    flat = " ".join(text.split())
    assert "up to 2000 N/m; the first wall that keeps vibrating is 2400 N/m (the thesis" in flat
    assert "(7.7 N s/m at Kf = 100 with the amplifier lag)" in flat
    assert "light grip the first wall that keeps vibrating is 2400 N/m, with a hand as on" in flat
    assert "5 N s/m) none up to 2400 N/m; the thesis does not say" in flat
    # the one configuration comes first, before any part's section
    assert text.index("## One plant and one observer configuration") < text.index("## Chapter 7")
    assert (
        "- [x] OL onset through the graph 2333 N/m within +-5 % of the linear model's 2314 N/m "
        "(bound without the amplifier lag 2544 N/m)"
    ) in " ".join(text.split())
    for fig in ("ch7_transparency.png", "ch6_onsets.png", "dob_kick_grid.png"):
        assert (tmp_path / "figures" / fig).is_file()


def test_dob_kf_100_sticks_with_friction_to_a_wall_and_vibrates_without() -> None:
    """The mechanism of the report's DOB section, cell by cell (chapter 6's tap, DOB Kf = 100,
    the configuration's observer): with the plant's friction the tap dies out at 2000 N/m and
    keeps a vibration at 2400 N/m (measured 0.0 and 329 um RMS at 25 Hz); without Coulomb
    friction 1600 N/m vibrates too; a gain above the chatter gain (10 N s/m) hunts at 800 N/m;
    a bench hand (0.1 kg, 300 N/m, 5 N s/m) instead of the light grip keeps 2400 N/m quiet."""
    base = SessionConfig.from_yaml(CONFIG).replace(law=law_for("DOB", 100.0))
    c = base.observer.gain
    quiet = dob.kick_point(base, 2000.0, c, True)
    loud = dob.kick_point(base, 2400.0, c, True)
    frictionless = dob.kick_point(base, 1600.0, c, False)
    hunting = dob.kick_point(base, 800.0, 10.0, True)
    bench = dob.grip_point(base, 2400.0, dob.GRIPS[1])  # a firmer, damped hand holds it
    assert not quiet.vibrates, quiet
    assert loud.vibrates and loud.residual_rms_m > 50 * dob.VIBRATION_RMS_M, loud
    assert 10.0 < loud.frequency_hz < 60.0, loud
    assert frictionless.vibrates, frictionless
    assert hunting.vibrates and hunting.residual_rms_m < 20 * dob.VIBRATION_RMS_M, hunting
    assert not bench.vibrates, bench


def test_a_recorded_run_counts_only_with_the_same_parameters(tmp_path) -> None:
    from haptic_sim.experiments.graph_runs import (
        COMPLETE,
        GraphRun,
        bag_path,
        is_complete,
        params_digest,
        run_dir,
    )

    cell = Cell("ch7", "OL", 0.0, 800.0)
    run = GraphRun("r", {"device_node": {"duration_s": 1.0}}, cell)
    bag_path(tmp_path, run).mkdir(parents=True)
    assert not is_complete(tmp_path, run)  # interrupted: no marker
    marker = {"wall_s": 1.0, "params_digest": params_digest(run)}
    (run_dir(tmp_path, run) / COMPLETE).write_text(json.dumps(marker))
    assert is_complete(tmp_path, run)
    changed = GraphRun("r", {"device_node": {"duration_s": 2.0}}, cell)
    assert not is_complete(tmp_path, changed)
