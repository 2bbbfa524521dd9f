"""haptic-identify --velocity-noise: the bridge's Kalman velocity filter from a bag's positions.

The bag holds a position-only driver's ``joint_states`` (no velocity, no effort): three joints,
two moved by white jerk of a known density and read to counts, one held still."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.cli.identify import main
from haptic_dob.core.kalman_velocity import process_noise, transition
from haptic_dob.runtime.params import load_node_params
from support.cli import exit_code
from support.joint_bags import write_joint_states

PSD = 800.0  # rad^2/s^5
COUNTS = (4e-4, 4e-4, 8e-4)
NAMES = ("waist", "shoulder", "elbow")


def jerk_motion(n: int, seed: int) -> np.ndarray:
    """A joint driven by white jerk of density ``PSD`` for ``n`` samples at 500 Hz (rad)."""
    rng = np.random.default_rng(seed)
    F, L = transition(0.002), np.linalg.cholesky(process_noise(PSD, 0.002))
    w = rng.standard_normal((n, 3)) @ L.T
    x, q = np.zeros(3), np.empty(n)
    for k in range(n):
        x = F @ x + w[k]
        q[k] = x[0]
    return q


@pytest.fixture(scope="module")
def bag(tmp_path_factory: pytest.TempPathFactory) -> Path:
    n = 10000
    q = np.column_stack([np.zeros(n), jerk_motion(n, 1), jerk_motion(n, 2)])
    q = np.round(q / np.array(COUNTS)) * np.array(COUNTS)
    stamps = 1_700_000_000 * 10**9 + np.arange(n, dtype=np.int64) * 2_000_000
    path = tmp_path_factory.mktemp("velocity") / "bag"
    return write_joint_states(path, stamps, NAMES, q, None, "sqlite3")


def test_the_density_is_found_and_written_for_the_bridge(
    bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The moving joints' density within 15 % (3 standard deviations of the estimate, test_
    kalman_velocity); the still waist named and left out; the params file sets the bridge's
    counts and density, which its settings accept."""
    out = tmp_path / "velocity.yaml"
    counts = ",".join(map(str, COUNTS))
    assert main([str(bag), "--velocity-noise", "--counts", counts, "--write-yaml", str(out)]) == 0
    table = capsys.readouterr().out
    assert "no (under 10 counts)" in table and f"bridge params written to {out}" in table
    bridge = load_node_params(out)["bridge_node"]
    assert bridge["state.encoder_resolution"] == list(COUNTS)
    (psd,) = bridge["state.velocity_jerk_psd"]
    assert psd == pytest.approx(PSD, rel=0.15)
    assert main([str(bag), "--velocity-noise", "--counts", counts, "--json"]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["fitted"] == ["shoulder", "elbow"] and fit["psd"] == pytest.approx(psd, rel=1e-5)
    assert fit["period_s"] == pytest.approx(0.002)


def test_one_count_serves_every_joint_and_joints_may_be_chosen(
    bag: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """With some joints chosen the file sets the density alone: their counts are not the
    bridge's list of every joint's."""
    out = tmp_path / "velocity.yaml"
    args = [str(bag), "--velocity-noise", "--counts", "4e-4", "--joints", "shoulder", "--json"]
    assert main([*args, "--write-yaml", str(out)]) == 0
    fit = json.loads(capsys.readouterr().out)
    assert fit["joints"] == ["shoulder"] and fit["psd"] == pytest.approx(PSD, rel=0.15)
    assert set(load_node_params(out)["bridge_node"]) == {"state.velocity_jerk_psd"}


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["--velocity-noise"], "--velocity-noise needs --counts"),
        (["--counts", "4e-4"], "--counts goes with --velocity-noise"),
        (["--velocity-noise", "--counts", "4e-4", "--urdf", "a.urdf"], "leave out --urdf"),
        (["--velocity-noise", "--counts", "4e-4", "--axes", "a,b,c"], "leave out --axes"),
        (["--velocity-noise", "--counts", "4e-4,0"], "--counts needs positive numbers"),
        (["--velocity-noise", "--counts", "1e-4,2e-4"], "--counts: give 1 or 3"),
        (["--velocity-noise", "--counts", "4e-4", "--joints", "waist"], "no joint moved 10"),
        (["--velocity-noise", "--counts", "1e-3"], "steps by 0.0004, under half the count"),
    ],
)
def test_bad_options_and_a_still_record_are_refused_in_one_line(
    bag: Path, capsys: pytest.CaptureFixture[str], args: list[str], says: str
) -> None:
    assert exit_code(main, [str(bag), *args]) == 2
    err = capsys.readouterr().err.strip()
    assert "Traceback" not in err
    # one line says what is wrong (argparse's refusals print the usage before it)
    last = err.splitlines()[-1]
    assert last.startswith("ERROR: ") and says in last and err.count("ERROR") == 1, err
