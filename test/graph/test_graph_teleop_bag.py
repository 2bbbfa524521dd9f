"""Metrics from a bag: the teleoperation graph recorded in lockstep (``haptic-launch teleop_sim
--record BAG``) and read back (``haptic-teleop --bag BAG``) gives the batch run's arrays and
figures, to the bit.

Bit for bit, not within a tolerance: the lockstep graph computes every sample as the batch run
does (test_graph_teleop.py), the bag holds the float64 values the nodes published, the values
derived from them (the master's point mapped to the slave, the rendered force in slave units)
go through the same functions row by row, and ``metrics()`` is the same code on equal arrays, so
no summation runs in another order."""

from __future__ import annotations

import dataclasses
import json

import numpy as np
import pytest

from haptic_sim.cli.teleop import _no_nan, main
from haptic_sim.teleop.bag import read_teleop_bag
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.session import run_teleop
from support.rosgraph import isolated_env, launch

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

DURATION_S = 1.0
CHANNEL = {
    "channel.round_trip_delay_ms": 10.0,
    "channel.jitter_ms": 3.0,
    "channel.passivity": True,
}


def test_a_recorded_teleop_graph_gives_the_batch_runs_figures(root, tmp_path, capsys) -> None:
    config = root / "config" / "teleop_sim.yaml"
    bag = tmp_path / "teleop_bag"
    sets = [f"**/device_node:duration_s={DURATION_S}"]
    sets += [f"**/channel_node:{k}={str(v).lower()}" for k, v in CHANNEL.items()]
    graph = launch(
        str(config), isolated_env(), sets, tmp_path / "launch.log", ["--record", str(bag)]
    )
    try:
        assert graph.wait(240) == 0, graph.output()
    finally:
        graph.stop()
    batch = run_teleop(
        TeleopConfig.from_yaml(config).override(
            {"/**/device_node": {"duration_s": DURATION_S}, "/**/channel_node": CHANNEL}
        )
    )
    recorded = read_teleop_bag(bag)
    assert recorded.samples_missing == 0
    got = recorded.result
    assert got.config.channel == batch.config.channel  # from the nodes' recorded parameters
    for field in dataclasses.fields(batch):
        if field.name != "config":
            assert np.array_equal(getattr(got, field.name), getattr(batch, field.name)), field.name
    assert np.any(batch.contact[:, 2] > 0.0) and batch.dissipated[-1] > 0.0  # it touched, TDPA
    want = _no_nan(dataclasses.asdict(batch.metrics()))
    assert _no_nan(dataclasses.asdict(got.metrics())) == want
    assert want["contact_pct"] > 0.0
    capsys.readouterr()
    assert main(["--bag", str(bag), "--json", "--out", str(tmp_path / "figures")]) == 0
    assert json.loads(capsys.readouterr().out) == want
    assert (tmp_path / "figures" / "force_tracking.png").stat().st_size > 0
