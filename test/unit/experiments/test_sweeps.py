"""The sweeps part: Table 7.1's cells that stay off, against the parameter responsible."""

from __future__ import annotations

from pathlib import Path

from haptic_sim.experiments import spread, spread_report, sweeps, sweeps_report
from haptic_sim.experiments.sweeps import (
    DEPTH,
    FRICTION,
    GRIP,
    OBSERVER,
    SENSOR,
    SweepCell,
    SweepStudy,
)
from haptic_sim.slide.session import SessionConfig

BASE = SessionConfig.from_yaml(Path(__file__).resolve().parents[3] / "config" / "slide_sim.yaml")


def test_no_grip_takes_open_loop_at_2400_to_the_thesiss_first_bins() -> None:
    """OL renders 2400 N/m soft up to 5 Hz, but with the chapter-7 grip or a looser one its band
    stays several Hz wide (the thesis: 0.6 Hz)."""
    for damping in (10.0, 2.0):
        c = sweeps._session((BASE, GRIP, "OL", 0.0, 2400.0, damping))
        assert c.mean_db_to_5hz is not None and -3.0 < c.mean_db_to_5hz < 0.0, c
        assert c.bandwidth_hz is not None and c.bandwidth_hz > 3.0 and not c.below_first_bin, c


def test_a_deeper_push_at_80_gives_the_open_loop_wall_its_coherence() -> None:
    """At 80 N/m the configuration's hand pushes about twice the friction and the handle sticks:
    the motion and the force hardly cohere and the band ends below the first bin; four times
    the depth moves the handle and the record coheres."""
    shallow = sweeps._session((BASE, DEPTH, "OL", 0.0, 80.0, 1.0))
    deep = sweeps._session((BASE, DEPTH, "OL", 0.0, 80.0, 4.0))
    assert shallow.below_first_bin and (shallow.coherence_in_band or 0.0) < 0.3, shallow
    assert (deep.coherence_in_band or 0.0) > 0.8 and not deep.below_first_bin, deep


def test_the_high_gain_dob_band_follows_the_observer_gain() -> None:
    """DOB Kf=25 at 1600 N/m: the band rises past +3 dB near the observer's corner c / (2 pi m),
    so it grows with c: the one node gain (7) against the rule's (30, the fastest that does not
    chatter at Kf = 25)."""
    slow = sweeps._session((BASE, OBSERVER, "DOB", 25.0, 1600.0, 7.0))
    fast = sweeps._session((BASE, OBSERVER, "DOB", 25.0, 1600.0, 30.0))
    assert slow.bandwidth_hz is not None and fast.bandwidth_hz is not None
    assert fast.bandwidth_hz > 2.5 * slow.bandwidth_hz
    assert slow.mean_db_to_5hz is not None and slow.mean_db_to_5hz > 1.0  # it leaves upward
    assert fast.saturated_pct < 10.0  # below the chatter limit: not at the force limit


def test_more_breakaway_friction_than_the_observer_knows_narrows_the_dob_bands() -> None:
    """DOB Kf=1 at 800 N/m: with the plant's breakaway friction at 2.5 times Coulomb (0.6 N, the
    bound where chapter 4.3's 0.6 N sine no longer moves the slide) the observer underestimates the
    force at low speed and the wall is rendered softer (thesis 7.3.3.1): the mean rendering up
    to 5 Hz falls by more than 1 dB and the band narrows (measured 4.91 to 2.48 Hz, -1.2 to
    -2.4 dB)."""
    mild = sweeps._session((BASE, FRICTION, "DOB", 1.0, 800.0, 1.5))
    strong = sweeps._session((BASE, FRICTION, "DOB", 1.0, 800.0, 2.5))
    assert mild.bandwidth_hz is not None and strong.bandwidth_hz is not None
    assert strong.bandwidth_hz < 0.6 * mild.bandwidth_hz
    assert mild.mean_db_to_5hz is not None and strong.mean_db_to_5hz is not None
    assert strong.mean_db_to_5hz < mild.mean_db_to_5hz - 1.0


def test_a_slow_sensor_lowers_the_cl_onset_before_it_lowers_the_band_much() -> None:
    """CL Kf=2 at 1600 N/m (the sweep's first wall, where it measures the onset): a 5 Hz sensor
    leaves a band above the thesis's 6.6 Hz while chapter 6's linear onset falls below the
    thesis's 800 N/m."""
    cell = sweeps._session((BASE, SENSOR, "CL", 2.0, 1600.0, 5.0))
    assert cell.bandwidth_hz is not None and cell.bandwidth_hz > 6.6
    assert cell.onset_n_per_m is not None and cell.onset_n_per_m < 700.0


def test_each_sweep_starts_from_the_chapter_7_value() -> None:
    assert GRIP.values_for(BASE, 0.0)[0] == BASE.hand.damping_n_s_per_m
    assert DEPTH.values_for(BASE, 2.0) == (1.0, 2.0, 4.0)
    assert OBSERVER.values_for(BASE, 1.0) == (146.0, 7.0, 10.0, 30.0)
    assert OBSERVER.values_for(BASE, 25.0) == (30.0, 7.0, 10.0, 146.0)
    assert FRICTION.values_for(BASE, 1.0) == (BASE.device.stiction_ratio, 2.0, 2.5)
    assert SENSOR.values_for(BASE.replace(sensor__bandwidth_hz=20.0), 2.0) == (20.0, 5.0)


WALL = {"grip": 2400.0, "depth": 80.0, "observer": 1600.0}


def _cell(
    sweep: str, mode: str, kf: float, value: float, bw: float, coh: float, sat: float
) -> SweepCell:
    db = -1.6 if bw > 1 else -3.1
    return SweepCell(
        sweep, mode, kf, WALL[sweep], value, bw, 30.0, coh, db, -1.8, sat, None, bw < 0.3
    )


def test_the_tables_and_the_text_come_from_the_cells() -> None:
    r = SweepStudy(
        [
            _cell("grip", "OL", 0.0, 10.0, 6.04, 0.85, 0.0),
            _cell("grip", "OL", 0.0, 5.0, 4.9, 0.64, 0.0),
            _cell("depth", "OL", 0.0, 1.0, 0.25, 0.09, 0.0),
            _cell("depth", "OL", 0.0, 4.0, 1.29, 0.90, 0.0),
            _cell("observer", "DOB", 1.0, 146.0, 6.0, 0.92, 0.0),
            _cell("observer", "DOB", 1.0, 7.0, 10.0, 0.76, 0.0),
            _cell("observer", "DOB", 25.0, 30.0, 10.0, 0.88, 4.0),
            _cell("observer", "DOB", 25.0, 7.0, 3.6, 0.89, 0.0),
        ],
        [
            spread.SeedCell(s, "OL", 0.0, 800.0, bw, bw < 0.3)
            for s, bw in ((0, 3.86), (1, 4.07), (2, 0.25))
        ],
    )
    grip = sweeps_report.sweep_table(r, GRIP)
    assert "| | 10 | 5 | thesis (Hz) |" in grip  # the values run, in their order
    assert "| OL | **6.04 (0.85); -1.6 / -1.8; 0 %** | 4.90 (0.64); -1.6 / -1.8; 0 % | 0.6 |" in (
        grip
    )  # chapter 7's value in bold
    assert "CL" not in grip.split("thesis (Hz) |")[1]  # a controller not swept has no row
    depth = sweeps_report.sweep_table(r, DEPTH)
    assert "| OL | **< 0.25 (0.09); -3.1 / -1.8; 0 %** | 1.29 (0.90)" in depth
    assert sweeps_report.sweep_table(r, SENSOR) == ""  # not run: no table
    obs = sweeps_report.sweep_table(r, OBSERVER)
    assert "| | 146 | 7 | 30 | thesis (Hz) |" in obs
    # each row's own chapter-7 value is the bold one
    assert "| DOB Kf=1, 1600 N/m | **6.00 (0.92); -1.6 / -1.8; 0 %** | 10.00 (0.76)" in obs
    assert "| DOB Kf=25, 1600 N/m | - | 3.60 (0.89); -1.6 / -1.8; 0 % | **10.00 (0.88)" in obs
    text = sweeps_report.grip_text(r)
    assert "10 N s/m: 6.04 Hz; 5 N s/m: 4.90 Hz (thesis 0.6 Hz)" in text
    assert "OL x1: < 0.25 Hz (coh. 0.09), x4: 1.29 Hz (coh. 0.90)" in sweeps_report.depth_text(r)
    assert "DOB Kf=1: c = 146 at 1600 N/m" in sweeps_report.observer_text(r)
    diffs = sweeps_report.differences(r)
    assert any("no mechanism found" in d and "(at least 4.90 Hz)" in d for d in diffs)
    assert any(
        "close to the frictional force" in d and "OL < 0.25 Hz (coherence 0.09)" in d for d in diffs
    )
    assert any("seed 0: 1, seed 1: 1, seed 2: 0; their median: 1 of 1" in d for d in diffs)
    table = spread_report.spread_table(r.seeds)
    assert "| OL, 800 N/m | 3.86* | 4.07* | < 0.25 | 3.86* | 3.8 |" in table
    assert "| within 15 % | 1 of 1 | 1 of 1 | 0 of 1 | 1 of 1 | |" in table
    checks = sweeps_report.checks(r)
    assert [c.passed for c in checks] == [False] * 4  # 1 of 16 is not 10
    assert "the median of 3 seeds of the hand: 1 of 1 cells" in checks[-1].text
    assert sweeps_report.grip_text(SweepStudy(r.cells[2:])) == ""
    assert sweeps_report.differences(SweepStudy([])) == []
    assert sweeps_report.depth_text(SweepStudy([])) == ""
    assert sweeps_report.checks(SweepStudy([])) == []


def test_the_median_of_the_seeds_is_no_value_where_it_falls_below_the_first_bin() -> None:
    cells = [
        spread.SeedCell(s, "OL", 0.0, 2400.0, bw, bw < 0.3)
        for s, bw in ((0, 0.25), (1, 0.25), (2, 0.6))
    ]
    assert spread.median_bandwidth(cells) is None  # "< 0.25" is a floor, not 0.25 Hz
    assert spread_report.median_count(cells) == 0
    cells[1] = spread.SeedCell(1, "OL", 0.0, 2400.0, 0.62)
    assert spread.median_bandwidth(cells) == 0.6 and spread_report.median_count(cells) == 1
