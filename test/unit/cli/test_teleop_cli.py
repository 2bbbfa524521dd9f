"""``haptic-teleop``: the figures as a table or one JSON line, the figures' files, bad input."""

from __future__ import annotations

import json
import subprocess

import pytest

from haptic_sim.cli import teleop as teleop_cli
from haptic_sim.cli.teleop import main
from haptic_sim.teleop.stability import DelayPoint
from support.paths import tool


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


def test_the_sweep_adds_its_table_and_figure(tmp_path, capsys, monkeypatch) -> None:
    """The sweep's plumbing, on made-up points (the sweep itself: test_teleop_session.py)."""
    asked = {}

    def fake_sweep(base, delays, protocol, workers):
        asked.update(delays=delays, workers=workers, delay=base.channel.round_trip_delay_ms)
        return [
            DelayPoint(
                d,
                p,
                0.0 if p or d < 20 else 12.0,
                -1.0 * (d >= 20 and not p),
                0.1 * p,
                9.0,
                p or d < 20,
            )
            for p in (False, True)
            for d in delays
        ]

    monkeypatch.setattr(teleop_cli, "delay_sweep", fake_sweep)
    argv = ["--duration", "0.2", "--sweep", "10:30:10", "--workers", "3", "--out", str(tmp_path)]
    assert main(argv) == 0
    assert asked == {"delays": [10.0, 20.0, 30.0], "workers": 3, "delay": 2.0}
    out = capsys.readouterr().out
    assert "plain channel: unstable from 20 ms" in out and "TDPA: stable at every delay" in out
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
