"""The sweeps part: Table 7.1's cells that stay off, against the parameter responsible."""

from __future__ import annotations

from pathlib import Path

from haptic_sim.experiments import sweeps
from haptic_sim.experiments.sweeps import FORCE_LIMIT, GRIP, SweepCell, SweepStudy
from haptic_sim.session import SessionConfig

BASE = SessionConfig.from_yaml(Path(__file__).resolve().parents[1] / "config" / "slide_sim.yaml")


def test_open_loop_at_2400_sits_at_the_edge_of_the_minus_3_db_criterion() -> None:
    """OL renders the wall 1.5-3 dB soft up to 5 Hz with either grip; the looser grip takes the
    first bin past -3 dB and the band ends there, while the mean barely moves."""
    firm = sweeps._session((BASE, GRIP, "OL", 0.0, 10.0))
    loose = sweeps._session((BASE, GRIP, "OL", 0.0, 5.0))
    # measured: 6.04 Hz, -1.6 / -1.6 dB; 0.50 Hz, -3.0 / -2.0 dB
    assert firm.bandwidth_hz is not None and firm.bandwidth_hz > 4.0
    assert loose.bandwidth_hz is not None and loose.bandwidth_hz < 1.0
    for c in (firm, loose):
        assert c.mean_db_to_5hz is not None and -3.0 < c.mean_db_to_5hz < -1.0
    assert loose.first_bin_db is not None and loose.first_bin_db <= -3.0 + 0.05
    assert firm.first_bin_db is not None and firm.first_bin_db > -2.5


def test_force_feedback_at_80_saturates_and_a_larger_limit_restores_the_band() -> None:
    at_4 = sweeps._session((BASE, FORCE_LIMIT, "CL", 2.0, 4.0))
    at_8 = sweeps._session((BASE, FORCE_LIMIT, "CL", 2.0, 8.0))
    # measured: 21 % at the limit, coherence 0.13, 0.50 Hz; 0.5 %, 0.95, 2.08 Hz
    assert at_4.saturated_pct > 10.0 and (at_4.coherence_in_band or 0.0) < 0.3
    assert at_8.saturated_pct < 2.0 and (at_8.coherence_in_band or 0.0) > 0.9
    assert (at_8.bandwidth_hz or 0.0) > 1.5 > (at_4.bandwidth_hz or 0.0)


def _cell(
    sweep: str, mode: str, kf: float, value: float, bw: float, coh: float, sat: float
) -> SweepCell:
    return SweepCell(sweep, mode, kf, value, bw, 30.0, coh, -1.6 if bw > 1 else -3.1, -1.8, sat)


def test_the_tables_and_the_text_come_from_the_cells() -> None:
    r = SweepStudy(
        [
            _cell("grip", "OL", 0.0, 10.0, 6.04, 0.85, 0.0),
            _cell("grip", "OL", 0.0, 5.0, 0.5, 0.64, 0.0),
            _cell("force_limit", "CL", 2.0, 4.0, 0.5, 0.13, 21.2),
            _cell("force_limit", "CL", 2.0, 8.0, 2.08, 0.95, 0.5),
        ]
    )
    grip = sweeps.sweep_table(r, GRIP)
    assert (
        "| OL | 6.04 (0.85); -1.6 / -1.8; 0 % | 0.50 (0.64); -3.1 / -1.8; 0 % | - | - | - | 0.6 |"
        in grip
    )
    assert "CL" not in grip.split("thesis (Hz) |")[1]  # a controller not swept has no row
    limit = sweeps.sweep_table(r, FORCE_LIMIT)
    assert (
        "| CL Kf=2 | 0.50 (0.13); -3.1 / -1.8; 21 % | 2.08 (0.95); -1.6 / -1.8; 0 % | - | - | 1.7 |"
        in limit
    )
    text = sweeps.grip_text(r)
    assert "keeps a 6.04 Hz band" in text and "With a looser grip (5 N s/m)" in text
    assert "CL Kf=2 spends 21 % of the session at the 4 N limit" in sweeps.limit_text(r)
    grip_diff, limit_diff = sweeps.differences(r)
    assert "goes from 6.04 Hz (10 N s/m grip) to 0.50 Hz (5 N s/m)" in grip_diff
    assert "CL Kf=2 is at the 4 N limit 21 % of the time" in limit_diff
    assert sweeps.grip_text(SweepStudy(r.cells[2:])) == ""
    assert sweeps.differences(SweepStudy([])) == [] and sweeps.limit_text(SweepStudy([])) == ""
