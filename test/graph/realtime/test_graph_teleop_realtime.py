"""The teleoperation graph in real time at 1 kHz, all in one process (``haptic-launch teleop_sim
--set '**/device_node:clock_mode=realtime'``): the loop closes over the channel, and when the
link dies (``channel.cut_at_s``) the master renders exactly zero force within the watchdog and
the slave holds where it is. Bounds in samples.

Each device ticks on its own clock, so a side's sample index is its whole periods since its
first sample (``SampleClock``), and the sides are apart by their start-up skew. The slave's last
message before the cut reaches the master at its sample ``C - 1 + max(delay, lag)`` (``lag``:
how far the slave is behind, measured from the test's readers; a slave ahead, ``lag`` < 0,
sends it ``-lag`` samples sooner in the master's samples); the master's end goes silent
``timeout`` samples later (21), as in batch. ``SLACK`` samples allow for the hand-over and the
lag's measurement. Skips where ``capacity.require_realtime_teleop`` says the machine cannot
carry the graph now. A process per side is not tested: a stall over the 20 ms watchdog makes
each end find its peer silent before any cut."""

from __future__ import annotations

import json

import numpy as np
import pytest

from haptic_msgs_py.stamps import stamp_ns
from support.capacity import require_realtime_teleop
from support.rosgraph import Collector, isolated_env, launch

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

DURATION_S = 3.0
CUT = 2000  # sample of the cut (channel.cut_at_s = 2 s at 1 kHz)
PERIOD_NS = 1_000_000
DELAY = 1  # samples each way (2 ms round trip)
TIMEOUT = 20  # samples of channel.timeout_s (20 ms): silent 21 samples after the last arrival
SLACK = 5  # samples: the hand-over to the next cycle and the lag's measurement
JS = "sensor_msgs/msg/JointState"
WAIT = {
    "master": "[observer_node, controller_node, channel_node, collector]",
    "slave": "[observer_node, slave_controller_node, channel_node, collector]",
}


def index(stamp: int, origin: int) -> int:
    """The sample index of a stamp of a side whose sample 0 is stamped ``origin`` (ns)."""
    return (stamp - origin + PERIOD_NS // 2) // PERIOD_NS


def link(col: Collector, topic: str) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray, int]:
    """A side's link messages: samples, receive times (s), peer silent, point (m), and the stamp
    of the side's sample 0 (its first message: the collector takes them all, reliably)."""
    times = np.array([t for t, _ in col.records[topic]])
    msgs = col.messages(topic)
    origin = stamp_ns(msgs[0])
    k = np.array([index(stamp_ns(m), origin) for m in msgs])
    silent = np.array([m.position[4] != 0.0 for m in msgs])
    point = np.array([list(m.position[:3]) for m in msgs])
    return k, times, silent, point, origin


def lag_at(k_a: np.ndarray, t_a: np.ndarray, k_b: np.ndarray, t_b: np.ndarray) -> int:
    """How many samples side b is behind side a when b's last message before the cut (sample
    ``CUT - 1``) came: a's newest sample then, less ``CUT - 1`` (negative when b is ahead). A side
    slower than real time keeps falling behind, so this is the lag that says when a gets it."""
    at = t_b[np.flatnonzero(k_b < CUT)[-1]]  # CUT - 1, or the last before it (missed ticks)
    newest_a = k_a[: np.searchsorted(t_a, at, side="right")].max()
    return int(newest_a - (CUT - 1))


def vectors(col: Collector, topic: str, origin: int) -> dict[int, np.ndarray]:
    """Sample -> the message's 3-vector, first of each sample (``origin``: sample 0's stamp)."""
    out: dict[int, np.ndarray] = {}
    for m in col.messages(topic):
        vec = m.wrench.force if hasattr(m, "wrench") else m.pose.position
        out.setdefault(index(stamp_ns(m), origin), np.array([vec.x, vec.y, vec.z]))
    return out


def test_realtime_teleop_closes_the_loop_and_falls_back_on_a_dead_link(root, tmp_path) -> None:
    watched = {
        "master": {"wrench_desired": "geometry_msgs/msg/WrenchStamped", "/teleop/to_slave": JS},
        "slave": {"pose_desired": "geometry_msgs/msg/PoseStamped", "/teleop/to_master": JS},
    }
    require_realtime_teleop(watched=watched)
    env = isolated_env()
    cols = {ns: Collector(env, topics, namespace=ns) for ns, topics in watched.items()}
    stats = {ns: tmp_path / f"{ns}.json" for ns in cols}
    sets = [
        "**/device_node:clock_mode=realtime",
        f"**/device_node:duration_s={DURATION_S}",
        f"**/channel_node:channel.cut_at_s={CUT / 1000}",
    ]
    sets += [f"{ns}/device_node:wait_for={w}" for ns, w in WAIT.items()]
    sets += [f"{ns}/device_node:stats_file={p}" for ns, p in stats.items()]
    config = str(root / "config" / "teleop_sim.yaml")
    graph = launch(config, env, sets, tmp_path / "launch.log")
    try:
        assert graph.wait(120) == 0, graph.output()
    finally:
        graph.stop()
        for col in reversed(cols.values()):
            col.close()
    # the loop closes at 1 kHz on both sides
    for ns, path in stats.items():
        s = json.loads(path.read_text())
        # both run to the end of the wall clock's 3 s
        assert s["cycles"] + s["missed_ticks"] >= 3000 and s["refused_commands"] == 0, (ns, s)
        assert s["commands_on_time"] + s["commands_late"] >= 0.9 * s["cycles"], (ns, s)
        assert s["on_time_pct"] > 50.0, (ns, s)
    mk, mt, m_silent, _, m0 = link(cols["master"], "/teleop/to_slave")
    sk, st, s_silent, s_disp, s0 = link(cols["slave"], "/teleop/to_master")
    rendered = vectors(cols["master"], "wrench_desired", m0)
    target = vectors(cols["slave"], "pose_desired", s0)
    before = [k for k in rendered if k < CUT]
    assert any(np.any(rendered[k] != 0.0) for k in before), "no force came back"
    first = min(target)
    moved = max(np.linalg.norm(target[k] - target[first]) for k in target if k < CUT)
    assert moved > 5e-3, "the master's motion did not reach the slave"
    # the dead link: each side notices within the watchdog after the peer's last message
    for name, k, silent, lag in (
        ("master", mk, m_silent, lag_at(mk, mt, sk, st)),
        ("slave", sk, s_silent, lag_at(sk, st, mk, mt)),
    ):
        assert np.any((k >= CUT) & silent), f"the {name}'s end never noticed the dead link"
        onset = int(k[(k >= CUT) & silent].min())
        latest = CUT + max(DELAY, lag + 1) + TIMEOUT + 1 + SLACK
        # a peer ahead (lag < 0: started that much before) sent its last message that much
        # sooner in this side's samples
        earliest = CUT + DELAY + TIMEOUT + min(0, lag)
        assert earliest <= onset <= latest, (name, onset, lag)
        assert np.all(silent[k >= onset]), name  # nothing comes back
        if name == "master":  # renders exactly zero from then on
            assert all(np.all(f == 0.0) for j, f in rendered.items() if j >= onset)
        else:  # holds the point where the slave was, and the slave stays there
            hold = target[onset]
            assert all(np.array_equal(p, hold) for j, p in target.items() if j >= onset)
            origin = target[first]  # the slave's point at its first sample (displacement 0)
            after = k >= onset
            assert np.max(np.linalg.norm(origin + s_disp[after] - hold, axis=1)) < 1e-3
