"""The grip part: Table 7.1's 2400 N/m column against the hand's grip damping (batch)."""

from __future__ import annotations

from pathlib import Path

from haptic_sim.experiments import grip
from haptic_sim.session import SessionConfig

BASE = SessionConfig.from_yaml(Path(__file__).resolve().parents[1] / "config" / "slide_sim.yaml")


def test_open_loop_at_2400_sits_at_the_edge_of_the_minus_3_db_criterion() -> None:
    """OL renders the wall 1.5-3 dB soft up to 5 Hz with either grip; the looser grip takes the
    first bin past -3 dB and the band ends there, while the mean barely moves."""
    firm = grip._session((BASE, "OL", 0.0, 10.0))
    loose = grip._session((BASE, "OL", 0.0, 5.0))
    # measured: 6.04 Hz, -1.6 / -1.6 dB; 0.50 Hz, -3.0 / -2.0 dB
    assert firm.bandwidth_hz is not None and firm.bandwidth_hz > 4.0
    assert loose.bandwidth_hz is not None and loose.bandwidth_hz < 1.0
    for c in (firm, loose):
        assert c.mean_db_to_5hz is not None and -3.0 < c.mean_db_to_5hz < -1.0
    assert loose.first_bin_db is not None and loose.first_bin_db <= -3.0 + 0.05
    assert firm.first_bin_db is not None and firm.first_bin_db > -2.5


def test_the_table_and_the_text_come_from_the_cells() -> None:
    r = grip.GripStudy(
        [
            grip.GripCell("OL", 0.0, 10.0, 6.04, 25.0, 0.85, -1.6, -1.5),
            grip.GripCell("OL", 0.0, 5.0, 0.5, 40.0, 0.64, -3.1, -2.0),
            grip.GripCell("CL", 2.0, 10.0, 10.0, 10.0, 0.99, -0.1, -0.3),
        ]
    )
    table = grip.grip_table(r)
    assert "| OL | 6.04 (0.85); -1.6, -1.5 | 0.50 (0.64); -3.1, -2.0 | 0.6 |" in table
    assert "| CL Kf=2 | 10.00 (0.99); -0.1, -0.3 | - | 4.5 |" in table  # 5 N s/m not run
    text = grip.grip_discussion(r)
    assert "keeps a 6.04 Hz band" in text and "With a looser grip (5 N s/m)" in text
    assert "at 0.50 Hz" in text
    assert grip.grip_discussion(grip.GripStudy(r.cells[2:])) == ""  # no OL: nothing to say
    (diff,) = grip.grip_difference(r)
    assert "goes from 6.04 Hz (10 N s/m grip) to 0.50 Hz (5 N s/m)" in diff
    assert grip.grip_difference(grip.GripStudy(r.cells[1:])) == []
