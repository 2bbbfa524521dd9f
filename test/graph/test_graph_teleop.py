"""The teleoperation graph in lockstep (haptic-launch teleop_sim): the master's and the slave's
nodes in /master and /slave, composed in one process (the default) or one process each,
reproduce the batch run bit for bit, through a channel with delay, jitter and passivity control,
or without it."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.session import run_teleop
from support.rosgraph import Collector, isolated_env, launch, resent

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

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


def first_of_each(messages: list, log: str) -> list:
    """Each sample once: a sample the device sent again (sample 0 until the graph was up, later
    ones after a lockstep timeout, each logged) comes again right after itself."""
    out = []
    for m in messages:
        if out and stamp_ns(m) == stamp_ns(out[-1]):
            assert stamp_ns(m) in [0, *resent(log)], stamp_ns(m)
            continue
        out.append(m)
    return out


@pytest.mark.parametrize("passivity", [True, False], ids=["passivity", "no_passivity"])
@pytest.mark.parametrize("layout", [[], ["--processes"]], ids=["composed", "processes"])
def test_the_teleop_graph_in_lockstep_equals_the_batch_run(
    root, tmp_path, layout, passivity: bool
) -> None:
    channel = {**CHANNEL, "channel.passivity": passivity}
    config = root / "config" / "teleop_sim.yaml"
    env = isolated_env()
    topic = {JOINT_STATES: SESSION_TOPICS[JOINT_STATES]}
    cols = {ns: Collector(env, topic, namespace=ns) for ns in ("master", "slave")}
    sets = [f"**/device_node:duration_s={CYCLES / 1000}"]
    sets += [f"{ns}/device_node:wait_for={w}" for ns, w in WAIT.items()]
    sets += [f"**/channel_node:{k}={str(v).lower()}" for k, v in channel.items()]
    graph = launch(str(config), env, sets, tmp_path / "launch.log", layout)
    try:
        assert graph.wait(240) == 0, graph.output()
        for ns, col in cols.items():
            assert col.wait_for_stamp(JOINT_STATES, CYCLES * 1_000_000, 10), (ns, graph.output())
    finally:
        graph.stop()
        for col in reversed(cols.values()):
            col.close()
    log = graph.output()
    got = {ns: first_of_each(col.messages(JOINT_STATES), log) for ns, col in cols.items()}
    batch = run_teleop(
        TeleopConfig.from_yaml(config).override(
            {"/**/device_node": {"duration_s": CYCLES / 1000}, "/**/channel_node": channel}
        )
    )
    for ns, msgs in got.items():
        assert [stamp_ns(m) for m in msgs] == [k * 1_000_000 for k in range(CYCLES + 1)], ns
    master_q = np.array([m.position[0] for m in got["master"]])[:CYCLES]
    slave_q = np.array([list(m.position) for m in got["slave"]])[:CYCLES]
    slave_effort = np.array([list(m.effort) for m in got["slave"]])[1 : CYCLES + 1]
    assert np.array_equal(master_q, batch.master_q)
    assert np.array_equal(slave_q, batch.slave_q)
    # the cycle contract on the wire: the slave's effort of sample k+1 is its command k
    assert np.array_equal(slave_effort, batch.slave_command)
    # the passivity controller acted (dissipated energy) or was off, and the slave touched the
    # table, so the equality above covers both
    assert (batch.dissipated[-1] > 0.0) == passivity and np.any(batch.contact[:, 2] > 0.0)
