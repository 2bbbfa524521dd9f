"""Real time follows the wall clock: a real-time device stamps each sample with the system clock
when it takes it, ticks on the wall clock's grid however loaded the machine (a late tick is an
overrun, and time does not slow), and ``/clock`` and ``/diagnostics`` say the same time as the
loop's topics.

No capacity premise: the point is what happens when the machine does not keep up.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pytest

from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import DIAGNOSTICS, JOINT_STATES, SESSION_TOPICS
from support.rosgraph import Collector, isolated_env, launch

pytestmark = [pytest.mark.multiprocess]

DURATION_S = 2.0
PERIOD_NS = 1_000_000


def test_a_realtime_run_is_stamped_by_the_system_clock_and_keeps_to_its_grid(root, tmp_path):
    watched = {
        JOINT_STATES: SESSION_TOPICS[JOINT_STATES],
        "/clock": "rosgraph_msgs/msg/Clock",
        DIAGNOSTICS: "diagnostic_msgs/msg/DiagnosticArray",
    }
    env = isolated_env()
    stats = tmp_path / "stats.json"
    col = Collector(env, watched)
    before = time.time_ns()
    graph = launch(
        str(root / "config" / "slide_sim.yaml"),
        env,
        [
            "device_node:clock_mode=realtime",
            f"device_node:duration_s={DURATION_S}",
            f"device_node:stats_file={stats}",
            "device_node:wait_for=[environment_node, observer_node, controller_node, collector]",
        ],
        tmp_path / "launch.log",
    )
    try:
        assert graph.wait(120) == 0, graph.output()
    finally:
        graph.stop()
        col.close()
    after = time.time_ns()
    s = json.loads(stats.read_text())
    joints = np.array([stamp_ns(m) for m in col.messages(JOINT_STATES)], dtype=np.int64)
    # every sample was stamped by the system clock while the run went on, in order
    assert joints.size > 0 and before < joints[0] and joints[-1] < after, (before, joints, after)
    assert np.all(np.diff(joints) > 0)
    # the grid: the run's last tick is due N = duration_s * rate_hz periods after sample 0,
    # however many ticks came late (each at most its missed ticks and one period late; a missed
    # tick is a sample fewer, not a later end); then the run ends (at shutdown one more period
    # runs at zero effort)
    n = round(DURATION_S * 1e9 / PERIOD_NS)
    assert s["cycles"] + s["missed_ticks"] >= n, s  # the last tick may itself be late
    last = joints[joints <= joints[0] + (n + s["missed_ticks"] + 1) * PERIOD_NS]
    span = int(last[-1] - joints[0]) if last.size > 1 else 0
    assert n * PERIOD_NS - PERIOD_NS <= span <= (n + s["missed_ticks"] + 1) * PERIOD_NS, (span, s)
    # /clock says the loop's stamps; /diagnostics (the node's system clock) the same time base
    clock = {m.clock.sec * 10**9 + m.clock.nanosec for m in col.messages("/clock")}
    assert clock and clock <= set(joints.tolist())
    diag = [
        m.header.stamp.sec * 10**9 + m.header.stamp.nanosec
        for m in col.messages(DIAGNOSTICS)
        if any(st.name == "/device_node" for st in m.status)
    ]
    assert diag and all(before < d < after for d in diag), (before, diag, after)
    assert any(joints[0] <= d <= joints[-1] for d in diag), (joints[[0, -1]], diag)
