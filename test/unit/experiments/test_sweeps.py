"""The sweeps part: Table 7.1's cells that stay off, against the parameter responsible."""

from __future__ import annotations

from pathlib import Path

from haptic_sim.experiments import spread, sweeps, sweeps_report
from haptic_sim.experiments.sweeps import FORCE_LIMIT, GRIP, OBSERVER, SENSOR, SweepCell, SweepStudy
from haptic_sim.slide.session import SessionConfig

BASE = SessionConfig.from_yaml(Path(__file__).resolve().parents[3] / "config" / "slide_sim.yaml")


def test_open_loop_at_2400_sits_at_the_edge_of_the_minus_3_db_criterion() -> None:
    """OL renders the wall 1.5-3 dB soft up to 5 Hz with either grip; the looser grip takes the
    first bin past -3 dB and the band ends there, while the mean barely moves."""
    firm = sweeps._session((BASE, GRIP, "OL", 0.0, 2400.0, 10.0))
    loose = sweeps._session((BASE, GRIP, "OL", 0.0, 2400.0, 5.0))
    # measured: 6.04 Hz, -1.6 / -1.6 dB; 0.50 Hz, -3.0 / -2.0 dB
    assert firm.bandwidth_hz is not None and firm.bandwidth_hz > 4.0
    assert loose.bandwidth_hz is not None and loose.bandwidth_hz < 1.0
    for c in (firm, loose):
        assert c.mean_db_to_5hz is not None and -3.0 < c.mean_db_to_5hz < -1.0
    assert loose.first_bin_db is not None and loose.first_bin_db <= -3.0 + 0.05
    assert firm.first_bin_db is not None and firm.first_bin_db > -2.5


def test_force_feedback_at_80_saturates_and_a_larger_limit_restores_the_band() -> None:
    at_4 = sweeps._session((BASE, FORCE_LIMIT, "CL", 2.0, 80.0, 4.0))
    at_8 = sweeps._session((BASE, FORCE_LIMIT, "CL", 2.0, 80.0, 8.0))
    # measured: 21 % at the limit, coherence 0.13, 0.50 Hz; 0.5 %, 0.95, 2.08 Hz
    assert at_4.saturated_pct > 10.0 and (at_4.coherence_in_band or 0.0) < 0.3
    assert at_8.saturated_pct < 2.0 and (at_8.coherence_in_band or 0.0) > 0.9
    assert (at_8.bandwidth_hz or 0.0) > 1.5 > (at_4.bandwidth_hz or 0.0)


def test_the_high_gain_dob_band_follows_the_observer_gain() -> None:
    """DOB Kf=25 at 1600 N/m: the band rises past +3 dB near the observer's corner c / (2 pi m),
    so it grows with c (measured 1.58 Hz at c = 4, 3.49 Hz at c = 10; 4 is not in the sweep)."""
    slow = sweeps._session((BASE, OBSERVER, "DOB", 25.0, 1600.0, 4.0))
    fast = sweeps._session((BASE, OBSERVER, "DOB", 25.0, 1600.0, 10.0))
    assert slow.bandwidth_hz is not None and fast.bandwidth_hz is not None
    assert fast.bandwidth_hz > 1.8 * slow.bandwidth_hz
    for c in (slow, fast):  # it leaves the band upward: the rendering rises with frequency
        assert c.mean_db_to_5hz is not None and c.mean_db_to_5hz > 1.0


def test_a_slow_sensor_lowers_the_cl_onset_before_it_lowers_the_band_much() -> None:
    """CL Kf=2 at 1600 N/m (the sweep's first wall, where it measures the onset): a 5 Hz sensor
    leaves a band above the thesis's 6.6 Hz (measured 7.55 Hz) while chapter 6's linear onset
    falls below the thesis's 800 N/m (588 N/m)."""
    cell = sweeps._session((BASE, SENSOR, "CL", 2.0, 1600.0, 5.0))
    assert cell.bandwidth_hz is not None and cell.bandwidth_hz > 6.6
    assert cell.onset_n_per_m is not None and cell.onset_n_per_m < 700.0


def test_each_sweep_starts_from_the_chapter_7_value() -> None:
    assert GRIP.values_for(BASE)[0] == BASE.hand.damping_n_s_per_m
    assert FORCE_LIMIT.values_for(BASE)[0] == BASE.device.max_force_n
    assert OBSERVER.values_for(BASE) == (BASE.observer.gain, 10.0, 41.6)
    assert SENSOR.values_for(BASE.replace(sensor__bandwidth_hz=20.0)) == (20.0, 5.0)


WALL = {"grip": 2400.0, "force_limit": 80.0, "observer": 1600.0}


def _cell(
    sweep: str, mode: str, kf: float, value: float, bw: float, coh: float, sat: float
) -> SweepCell:
    db = -1.6 if bw > 1 else -3.1
    return SweepCell(sweep, mode, kf, WALL[sweep], value, bw, 30.0, coh, db, -1.8, sat)


def test_the_tables_and_the_text_come_from_the_cells() -> None:
    r = SweepStudy(
        [
            _cell("grip", "OL", 0.0, 10.0, 6.04, 0.85, 0.0),
            _cell("grip", "OL", 0.0, 5.0, 0.5, 0.64, 0.0),
            _cell("force_limit", "CL", 2.0, 4.0, 0.5, 0.13, 21.2),
            _cell("force_limit", "CL", 2.0, 8.0, 2.08, 0.95, 0.5),
            _cell("observer", "DOB", 1.0, 7.0, 10.0, 0.89, 0.0),
            _cell("observer", "DOB", 25.0, 7.0, 3.6, 0.89, 0.0),
            _cell("observer", "DOB", 25.0, 41.6, 10.0, 1.0, 42.0),
        ],
        [
            spread.SeedCell(s, "OL", 0.0, 800.0, bw)
            for s, bw in ((0, 3.86), (1, 4.07), (2, 3.2), (3, 5.0))
        ],
    )
    grip = sweeps.sweep_table(r, GRIP)
    assert "| | 10 | 5 | thesis (Hz) |" in grip  # the values run, in their order
    assert "| OL | 6.04 (0.85); -1.6 / -1.8; 0 % | 0.50 (0.64); -3.1 / -1.8; 0 % | 0.6 |" in grip
    assert "CL" not in grip.split("thesis (Hz) |")[1]  # a controller not swept has no row
    limit = sweeps.sweep_table(r, FORCE_LIMIT)
    assert "| CL Kf=2 | 0.50 (0.13); -3.1 / -1.8; 21 % | 2.08 (0.95); -1.6 / -1.8; 0 % | 1.7 |" in (
        limit
    )
    assert sweeps.sweep_table(r, SENSOR) == ""  # not run: no table
    text = sweeps_report.grip_text(r)
    assert "keeps a 6.04 Hz band" in text and "With a looser grip (5 N s/m)" in text
    assert "CL Kf=2 spends 21 % of the session at the 4 N limit" in sweeps_report.limit_text(r)
    obs = sweeps_report.observer_text(r)
    assert "DOB Kf=1: c = none of the sweep's values at 1600 N/m; DOB Kf=25: c = 7 at 1600" in obs
    assert "(DOB Kf=25 at 1600 N/m with c = 41.6: the command at the force limit 42 %" in obs
    table = sweeps.sweep_table(r, OBSERVER)
    assert "| DOB Kf=25, 1600 N/m | 3.60 (0.89); -1.6 / -1.8; 0 % | 10.00 (1.00)" in table
    grip_diff, limit_diff, observer_diff, seeds_diff = sweeps_report.differences(r)
    assert "goes from 6.04 Hz (10 N s/m grip) to 0.50 Hz (5 N s/m)" in grip_diff
    assert "CL Kf=2 is at the 4 N limit 21 % of the time" in limit_diff
    assert "The DOB rows hang on the observer gain" in observer_diff
    assert "seed 0: 1, seed 1: 1, seed 2: 0, seed 3: 0 of 1 (the sweeps section)" in seeds_diff
    table = spread.spread_table(r.seeds)
    assert "| OL, 800 N/m | 3.86* | 4.07* | 3.20 | 5.00 | 3.8 |" in table
    assert "| within 15 % | 1 of 1 | 1 of 1 | 0 of 1 | 0 of 1 | |" in table
    assert sweeps_report.grip_text(SweepStudy(r.cells[2:])) == ""
    assert sweeps_report.differences(SweepStudy([])) == []
    assert sweeps_report.limit_text(SweepStudy([])) == ""
