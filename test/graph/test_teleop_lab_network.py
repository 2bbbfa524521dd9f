"""The teleoperation graph split across two hosts: the master's nodes in one network namespace,
the slave's in another (``haptic-launch teleop_sim --only master|slave --network subnet``), joined
by a veth pair. In lockstep the channel's link crosses the network and the run still reproduces
the batch run bit for bit: both arms' joint positions and the slave's efforts, sample for sample.
Needs root and ``ip`` (iproute2)."""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np
import pytest

from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.session import run_teleop
from support.netns import in_ns, lab_hosts
from support.rosgraph import isolated_env, resent
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

BIN = Path(sys.executable).parent
CYCLES = 1000
CHANNEL = {
    "channel.round_trip_delay_ms": 10.0,
    "channel.jitter_ms": 3.0,
    "channel.passivity": True,
}
WAIT = {
    "master": "[observer_node, controller_node, channel_node, collector]",
    "slave": "[observer_node, slave_controller_node, channel_node, collector]",
}


@pytest.fixture
def hosts():
    """Two network namespaces joined by a veth pair; yields (nsA, nsB, ifA)."""
    with lab_hosts() as made:
        yield made


def samples(rows: list[dict], ns: str, log: str) -> list[dict]:
    """A side's joint states, each sample once (sample 0 until the graph was up, and samples the
    device logged sending again after a lockstep timeout, come again right after themselves)."""
    out: list[dict] = []
    for r in (r for r in rows if r["ns"] == ns):
        if out and r["stamp"] == out[-1]["stamp"]:
            assert r["stamp"] in [0, *resent(log)], r["stamp"]
            continue
        out.append(r)
    return out


def test_the_slave_on_another_host_in_lockstep_equals_the_batch_run(hosts, root, tmp_path) -> None:
    ns_a, ns_b, _ = hosts
    config = root / "config" / "teleop_sim.yaml"
    env = isolated_env()
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "SUBNET"  # the collector's; the launches say --network
    env["PYTHONPATH"] = str(root / "test")  # the collector runs as ``-m support.netns_collect``
    sets = [f"**/device_node:duration_s={CYCLES / 1000}"]
    sets += [f"{ns}/device_node:wait_for={w}" for ns, w in WAIT.items()]
    sets += [f"**/channel_node:{k}={str(v).lower()}" for k, v in CHANNEL.items()]
    argv = [str(BIN / "haptic-launch"), str(config), "--network", "subnet"]
    argv += [a for s in sets for a in ("--set", s)]
    out = tmp_path / "joint_states.jsonl"
    collect = [str(BIN / "python"), "-m", "support.netns_collect", str(out)]
    collector = in_ns(ns_a, [*collect, "master", "slave"], env, tmp_path / "collector.log")
    sides = {}
    try:
        sides["slave"] = in_ns(ns_b, [*argv, "--only", "slave"], env, tmp_path / "slave.log")
        sides["master"] = in_ns(ns_a, [*argv, "--only", "master"], env, tmp_path / "master.log")
        for name, side in sides.items():
            assert side.wait(240) == 0, (name, side.output()[-3000:])
        assert wait_until(lambda: "ready" in collector.output(), 10), collector.output()
    finally:
        for side in sides.values():
            side.stop()
        collector.stop(30)
    rows = [json.loads(line) for line in out.read_text().splitlines()]
    logs = {name: side.output() for name, side in sides.items()}
    got = {ns: samples(rows, ns, logs[ns]) for ns in ("master", "slave")}
    for ns, msgs in got.items():
        assert [m["stamp"] for m in msgs] == [k * 1_000_000 for k in range(CYCLES + 1)], ns
    batch = run_teleop(
        TeleopConfig.from_yaml(config).override(
            {"/**/device_node": {"duration_s": CYCLES / 1000}, "/**/channel_node": CHANNEL}
        )
    )
    master_q = np.array([m["position"][0] for m in got["master"]])[:CYCLES]
    slave_q = np.array([m["position"] for m in got["slave"]])[:CYCLES]
    slave_effort = np.array([m["effort"] for m in got["slave"]])[1 : CYCLES + 1]
    assert np.array_equal(master_q, batch.master_q)
    assert np.array_equal(slave_q, batch.slave_q)
    assert np.array_equal(slave_effort, batch.slave_command)  # effort of k+1 = command k
    # the link crossed the network both ways and mattered: the slave touched the table, the
    # passivity controller acted, and the master felt the slave's force
    assert batch.dissipated[-1] > 0.0 and np.any(batch.contact[:, 2] > 0.0)
    assert np.any(np.array([m["effort"][0] for m in got["master"]]) != 0.0)
