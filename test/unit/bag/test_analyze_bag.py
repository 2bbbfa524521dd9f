"""Bag analysis: analytic impedance, segments at parameter changes, batch round trip, outputs."""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.bag import AnalysisSettings, Selection, analyze_arrays, analyze_bag, read_bag
from haptic_dob.bag.write import ParamChange, write_session_bag
from haptic_dob.cli.analyze import main
from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_sim.slide.session import SessionConfig, run_session
from support.bagdata import msd_band_edge_hz, msd_record, session_params

FS = 1000.0
M, B, K = 0.5, 2.0, 800.0


@pytest.fixture(scope="module")
def msd_bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """40 s of an exact mass-spring-damper (m 0.5 kg, b 2 N s/m, K 800 N/m), OL at 800 N/m."""
    x, f, v = msd_record(40.0, FS, M, B, K, seed=1)
    path = tmp_path_factory.mktemp("msd") / "msd"
    write_session_bag(path, x, f, FS, session_params("OL", 0.0, K), velocity=v)
    return path


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_known_impedance_gives_the_analytic_bandwidth(tmp_path: Path, storage: str) -> None:
    x, f, v = msd_record(40.0, FS, M, B, K, seed=1)
    path = tmp_path / "msd"
    write_session_bag(path, x, f, FS, session_params("OL", 0.0, K), velocity=v, storage=storage)
    a = analyze_bag(path)
    assert a.storage == storage
    (seg,) = a.segments
    expected = msd_band_edge_hz(M, B, K)  # 3.43 Hz
    tr = seg.figures.transparency
    assert tr is not None
    assert tr.bandwidth_hz == pytest.approx(expected, rel=0.05)
    assert not tr.band_limited_by_fmax
    # inside the band the H1 estimate is the impedance K - m w^2 + j b w itself
    w = 2 * np.pi * tr.freqs_hz
    inside = tr.freqs_hz <= tr.bandwidth_hz
    z = K - M * w**2 + 1j * B * w
    assert np.allclose(tr.impedance[inside], z[inside], rtol=0.02)
    assert seg.stiffness_source == "recorded" and seg.stiffness_n_per_m == K
    assert seg.controller == "OL"
    assert a.velocity_source == "/ee_twist"


def test_stiffness_option_overrides_the_recorded_one(msd_bag: Path) -> None:
    a = analyze_bag(msd_bag, settings=AnalysisSettings(stiffness_n_per_m=1600.0))
    (seg,) = a.segments
    assert seg.stiffness_source == "--stiffness" and seg.stiffness_n_per_m == 1600.0
    assert seg.figures.transparency is not None
    # against 1600 N/m the rendered 800 N/m is 6 dB low from the first bin: the band ends below
    # it (0.25 Hz with the 4 s segments)
    tr = seg.figures.transparency
    assert tr.bandwidth_hz == pytest.approx(0.25) and tr.band_below_first_bin
    assert seg.as_dict()["band_below_first_bin"] is True


def test_mode_switch_gives_two_labelled_segments(tmp_path: Path) -> None:
    """OL (m 0.5 kg) for 20 s, then DOB Kf=1 halves the felt mass: two segments, each its own."""
    x1, f1, v1 = msd_record(20.0, FS, M, B, K, seed=2)
    x2, f2, v2 = msd_record(20.0, FS, M / 2, B, K, seed=3)
    x, f, v = np.concatenate([x1, x2]), np.concatenate([f1, f2]), np.concatenate([v1, v2])
    change = ParamChange(20_000, "controller_node", {"mode": "DOB", "kf": 1.0})
    path = tmp_path / "switch"
    write_session_bag(path, x, f, FS, session_params("OL", 0.0, K), [change], velocity=v)
    a = analyze_bag(path)
    assert [s.controller for s in a.segments] == ["OL", "DOB"]
    assert [s.label for s in a.segments] == ["OL, 800 N/m", "DOB Kf=1, 800 N/m"]
    s0, s1 = a.segments
    assert (s0.segment.start, s0.segment.stop, s1.segment.start, s1.segment.stop) == (
        0,
        20_000,
        20_000,
        40_000,
    )
    assert s0.start_s == 0.0 and s0.end_s == s1.start_s == 20.0
    assert s1.analysed_from_s == pytest.approx(20.5)  # the transient after the change
    assert s1.segment.changed[0].values == {"mode": "DOB", "kf": 1.0}
    for seg, mass in ((s0, M), (s1, M / 2)):
        tr = seg.figures.transparency
        assert tr is not None
        assert tr.bandwidth_hz == pytest.approx(msd_band_edge_hz(mass, B, K), rel=0.05)
    # the JSON carries the labels and parameters
    rows = [r.as_dict() for r in a.segments]
    assert [(r["controller"], r["kf"]) for r in rows] == [("OL", 0.0), ("DOB", 1.0)]
    assert rows[1]["parameters"]["controller_node"]["mode"] == "DOB"


def test_irrelevant_or_repeated_parameter_events_do_not_split(tmp_path: Path) -> None:
    x, f, v = msd_record(10.0, FS, M, B, K, seed=4)
    changes = [
        ParamChange(3000, "controller_node", {"mode": "OL"}),  # the same value again
        ParamChange(4000, "device_node", {"duration_s": 5.0}),  # not a rendering parameter
        ParamChange(5000, "other_node", {"kf": 3.0}),  # another node
    ]
    path = tmp_path / "same"
    write_session_bag(path, x, f, FS, session_params(), changes, velocity=v)
    assert len(analyze_bag(path).segments) == 1


def short_session(mode: ControlMode, kf: float, seconds: float = 12.0):
    cfg = SessionConfig.from_yaml(Path(__file__).resolve().parents[3] / "config" / "slide_sim.yaml")
    cfg = cfg.replace(law=ImpedanceLaw(mode, kf, 4.0), loop__duration_s=seconds)
    return run_session(cfg)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_batch_session_round_trip_equals_the_in_process_summary(tmp_path: Path, storage) -> None:
    """A batch session written as a recorded bag analyses to exactly ``SessionResult.summary()``."""
    res = short_session(ControlMode.DOB, 1.0)
    path = tmp_path / "session"
    write_session_bag(
        path,
        res.q,
        res.force_measured,
        FS,
        session_params("DOB", 1.0, 800.0),
        velocity=res.qd,
        storage=storage,
        all_topics=True,
    )
    data = read_bag(path)
    assert np.array_equal(data.motion.values, res.q)
    assert np.array_equal(data.force.values, res.force_measured)
    assert data.velocity is not None and np.array_equal(data.velocity.values, res.qd)
    (seg,) = analyze_bag(path).segments
    got, want = seg.as_dict(), res.summary()
    for key in (
        "bandwidth_hz",
        "impedance_error_pct",
        "coherence_in_band",
        "max_active_energy_j",
        "in_contact_pct",
        "controller",
        "kf",
        "stiffness_n_per_m",
    ):
        assert got[key] == getattr(want, key), key
    assert got["analysed_from_s"] == 2.0


def test_joint_state_motion_gives_the_same_figures(tmp_path: Path) -> None:
    res = short_session(ControlMode.OL, 0.0)
    path = tmp_path / "js"
    write_session_bag(
        path, res.q, res.force_measured, FS, session_params(), velocity=res.qd, all_topics=True
    )
    pose = analyze_bag(path).segments[0].as_dict()
    js = analyze_bag(path, Selection(motion_topic="joint_states", joint="slide"))
    joint = js.segments[0].as_dict()
    assert js.velocity_source == "/joint_states"
    for key in ("bandwidth_hz", "impedance_error_pct", "max_active_energy_j"):
        assert joint[key] == pose[key]


def test_vibration_is_detected_in_contact_and_not_in_a_stable_session() -> None:
    from haptic_sim.slide.stability import StabilityProtocol

    cfg = SessionConfig.from_yaml(Path(__file__).resolve().parents[3] / "config" / "slide_sim.yaml")
    proto = StabilityProtocol(observe_s=6.0)
    fs = FS
    figures = {}
    for k in (2000.0, 3000.0):  # OL onset is 2538 N/m: below it decays, above it grows
        res = run_session(proto.session(cfg, k))
        s = slice(1600, None)  # after the ramp, from the pulse on
        figures[k] = analyze_arrays(
            res.q[s], res.force_measured[s], res.qd[s], fs, k, penetration=res.q[s]
        )
    stable = short_session(ControlMode.OL, 0.0, 20.0)
    s = slice(2000, None)
    figures[800.0] = analyze_arrays(
        stable.q[s], stable.force_measured[s], stable.qd[s], fs, 800.0, penetration=stable.q[s]
    )
    osc = {k: f.oscillation for k, f in figures.items() if f.oscillation is not None}
    assert len(osc) == len(figures)
    assert osc[3000.0].vibrating and osc[3000.0].growth_per_s > 0.1
    assert 12.0 <= osc[3000.0].frequency_hz <= 16.0
    assert not osc[2000.0].vibrating and osc[2000.0].growth_per_s < 0
    assert not osc[800.0].vibrating
    assert osc[800.0].peak_fraction < 0.7
    # the passivity observer of the growing one finds the device delivering energy
    assert figures[3000.0].energy.max_active_j > figures[2000.0].energy.max_active_j


def run_cli(args: list[str], capsys: pytest.CaptureFixture[str]) -> tuple[int, str, str]:
    code = main(args)
    out, err = capsys.readouterr()
    return code, out, err


def test_cli_json_csv_and_table(msd_bag: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run_cli([str(msd_bag), "--json"], capsys)
    assert code == 0, err
    (row,) = json.loads(out)
    for key in (
        "bag",
        "controller",
        "kf",
        "stiffness_n_per_m",
        "bandwidth_hz",
        "impedance_error_pct",
        "duration_s",
    ):
        assert key in row
    assert row["bag"] == str(msd_bag) and row["controller"] == "OL"
    assert row["duration_s"] == 40.0 and row["analysed_s"] == 38.0
    code, out, _ = run_cli([str(msd_bag), "--csv"], capsys)
    assert code == 0
    (csv_row,) = list(csv.DictReader(io.StringIO(out)))
    assert float(csv_row["bandwidth_hz"]) == row["bandwidth_hz"]
    code, out, _ = run_cli([str(msd_bag)], capsys)
    assert code == 0
    assert "OL" in out and f"{row['bandwidth_hz']:.2f} Hz" in out
    code, out, _ = run_cli([str(msd_bag), "--fmax", "2"], capsys)
    assert code == 0 and ">=2.00 Hz" in out  # the band reaches fmax


def test_several_bags_give_the_thesis_tables(tmp_path: Path, capsys) -> None:
    bags = []
    for mode, kf, k, m in (
        ("OL", 0.0, 800.0, 0.5),
        ("OL", 0.0, 1600.0, 0.5),
        ("CL", 2.0, 800.0, 0.5 / 3),
    ):
        x, f, v = msd_record(20.0, FS, m, B, k, seed=5)
        p = tmp_path / f"{mode}_{k:g}"
        write_session_bag(p, x, f, FS, session_params(mode, kf, k), velocity=v)
        bags.append(str(p))
    code, out, err = run_cli(bags, capsys)
    assert code == 0, err
    table = out[out.index("bandwidth (Hz), controllers by wall stiffness:") :]
    lines = table.splitlines()
    assert lines[1].split() == ["controller", "800", "N/m", "1600", "N/m"]
    assert lines[2].split()[0] == "OL" and lines[3].split()[:2] == ["CL", "Kf=2"]
    ol_800 = float(lines[2].split()[1])
    assert ol_800 == pytest.approx(msd_band_edge_hz(0.5, B, 800.0), rel=0.05)
    assert lines[3].split()[3] == "-"  # no CL run at 1600 N/m
    assert "average normalized impedance error inside the band (%)" in out


def test_plots_are_written(msd_bag: Path, tmp_path: Path, capsys) -> None:
    code, _, err = run_cli([str(msd_bag), "--plot", str(tmp_path / "fig")], capsys)
    assert code == 0, err
    files = sorted(p.name for p in (tmp_path / "fig").iterdir())
    assert files == ["msd_seg0_error.png", "msd_seg0_traces.png", "msd_seg0_transparency.png"]
    for name in files:
        assert (tmp_path / "fig" / name).read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_a_vibration_burst_is_found_window_by_window() -> None:
    """60 s of broadband motion with a 14 Hz, 0.5 mm oscillation from 20 s to 40 s only."""
    x, f, v = msd_record(60.0, FS, M, B, K, seed=6)
    t = np.arange(x.size) / FS
    burst = (t >= 20.0) & (t < 40.0)
    x = x + np.where(burst, 5e-4 * np.sin(2 * np.pi * 14.0 * t), 0.0)
    figs = analyze_arrays(x, f, v, FS, K, penetration=x)
    osc = figs.oscillation
    assert osc is not None and osc.windows == 3
    assert osc.vibrating and osc.vibrating_s == 20.0
    assert osc.frequency_hz == 14.0 and osc.amplitude_m == pytest.approx(5e-4, rel=0.1)
    quiet = analyze_arrays(x[:20_000], f[:20_000], v[:20_000], FS, K, penetration=x[:20_000])
    assert quiet.oscillation is not None and not quiet.oscillation.vibrating
