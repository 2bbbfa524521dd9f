"""haptic-session: a batch session from the command line."""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from support.paths import tool


def session(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [tool("haptic-session"), *args], capture_output=True, text=True, timeout=120
    )


def test_json_summary_and_saved_arrays(tmp_path) -> None:
    npz = tmp_path / "run.npz"
    out = session(
        "--controller", "DOB", "--kf", "1", "--duration", "5", "--json", "--save", str(npz)
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["controller"] == "DOB" and data["kf"] == 1.0 and data["duration_s"] == 5.0
    arrays = np.load(npz)
    assert arrays["q"].shape == (5000,) and set(arrays) >= {"t", "command", "force_estimated"}


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--stiffness", "-3"], "ERROR: --stiffness must be > 0"),
        (["--kf", "-2"], "ERROR: kf must be >= 0"),
        (["--duration", "0"], "ERROR: --duration must be > 0"),
        (["--config", "nope"], "ERROR: no config 'nope'"),
        (["--save", "/nonexistent-dir/x.npz", "--duration", "1"], "ERROR: "),
    ],
)
def test_bad_input(args: list[str], message: str) -> None:
    out = session(*args)
    assert out.returncode == 2 and message in out.stderr and "Traceback" not in out.stderr


def test_a_cartesian_device_session_gives_the_estimate_in_contact(tmp_path) -> None:
    """``--config point_mass_sim``: the point-mass device's session in batch, overridden."""
    npz = tmp_path / "run.npz"
    out = session(
        "--config", "point_mass_sim", "--duration", "3", "--kf", "2", "--json", "--save", str(npz)
    )
    assert out.returncode == 0, out.stderr
    data = json.loads(out.stdout)
    assert data["model"] == "point_mass" and data["kf"] == 2.0 and data["duration_s"] == 3.0
    assert data["in_contact_pct"] > 90.0 and 0.0 < data["estimate_rms_error_in_contact_n"] < 0.3
    assert np.load(npz)["q"].shape == (3000, 3)
    bad = session("--config", "point_mass_sim", "--kf", "-1")
    assert bad.returncode == 2 and bad.stderr.startswith("ERROR: --kf must be >= 0")
