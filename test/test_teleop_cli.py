"""``haptic-teleop``: the figures as a table or one JSON line, the figures' files, bad input."""

from __future__ import annotations

import json
import subprocess

import pytest

from conftest import tool
from haptic_sim.teleop_cli import main


def test_json_is_one_line_of_the_session_figures(capsys) -> None:
    assert main(["--duration", "1.0", "--delay-ms", "10", "--passivity", "--json"]) == 0
    out = capsys.readouterr().out
    assert out.count("\n") == 1
    doc = json.loads(out)
    assert doc["round_trip_delay_ms"] == 10.0 and doc["passivity"] is True
    assert doc["duration_s"] == 1.0 and doc["architecture"] == "position_force"
    assert doc["channel_energy_min_j"] >= -1e-9  # passivity control keeps it passive


def test_the_table_and_the_force_tracking_figure(tmp_path, capsys) -> None:
    argv = ["--duration", "1.0", "--observer", "momentum", "--out", str(tmp_path / "fig")]
    assert main([*argv, "--set", "/slave/observer_node:gain=200.0"]) == 0
    out = capsys.readouterr().out
    assert "estimate error (contact)" in out and "channel energy, lowest" in out
    assert (tmp_path / "fig" / "force_tracking.png").stat().st_size > 10_000


@pytest.mark.slow
def test_the_sweep_adds_its_table_and_figure(tmp_path, capsys) -> None:
    argv = ["--duration", "0.5", "--sweep", "50:50:1", "--workers", "2", "--out", str(tmp_path)]
    assert main(argv) == 0
    out = capsys.readouterr().out
    assert "plain channel: unstable from 50 ms" in out and "TDPA: stable at every delay" in out
    assert (tmp_path / "stability.png").stat().st_size > 10_000


@pytest.mark.parametrize(
    ("args", "says"),
    [
        (["nosuch"], "no config 'nosuch'"),
        (["--delay-ms", "-5"], "round_trip_delay_ms must be >= 0"),
        (["--set", "seed=3"], "--set needs SECTION:PARAM=VALUE"),
        (["--set", "/master/device_node:seed=abc"], "seed must be an integer"),
        (["--set", "/master/nosuch_node:x=1"], "name no node of the teleoperation graph"),
        (["--sweep", "0:10:5"], "--sweep needs 0 < FROM <= TO"),
        (["--jitter-ms", "30"], "must exceed the jitter"),
    ],
)
def test_bad_input_is_one_error_line_and_exit_2(args, says, capsys) -> None:
    assert main([*args, "--duration", "0.01"]) == 2
    err = capsys.readouterr().err
    assert err.startswith("ERROR: ") and err.count("\n") == 1 and says in err, err


def test_the_installed_command_refuses_bad_input_without_a_traceback() -> None:
    out = subprocess.run(
        [tool("haptic-teleop"), "--architecture", "wave_variables"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 2 and "Traceback" not in out.stderr
    assert "ERROR: argument --architecture: invalid choice" in out.stderr
