"""The loop through the bridge, in real time, against each test driver from its YAML alone.

For each profile a test driver ticks its plant on the wall clock (forcedimension_ros2-like at
1 kHz, Touch-like at 500 Hz with best-effort position-only states and the stylus button gating
the force, a Franka-like arm at 1 kHz as a teleoperation slave) and ``haptic-launch`` runs the
config with the bridge composed with the loop. Each asserts that the loop closes at the driver's
rate (commands for most states, most of them before the driver's next state, as measured by the
driver), that nothing is refused, and that the wall (the arm's table) is rendered, from the
driver's truth. The share of commands on time is a benchmark (``scripts/benchmarks.py
bridge``), not asserted here beyond "most". The loop runs under SCHED_FIFO (and a PM QoS
request) where this machine allows them, as a lab runs it: under default scheduling beside a
CPU hog the arm's loop got 32 % of its commands on time. Skips where the suite's capacity
measurement says this machine cannot carry a composed loop in real time now, or the bridge's
path with its raw DDS hop.
"""

from __future__ import annotations

import json
import time
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.models.urdf import UrdfModel
from support.capacity import hop_floor_us, require_path_latency, require_realtime
from support.drivers import scheduling
from support.drivers.run import DRIVER_SHARE, ON_TIME, SLIDE_HAND, Truth, bridge_session, start
from support.paths import ROOT
from support.rosgraph import Collector, isolated_env, launch

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

LOOP = ["bridge_node", "environment_node", "observer_node", "controller_node"]
RUN_S = 4.0
SLIDE_LOOP = ["device_node", "environment_node", "observer_node", "controller_node"]


def premise(path: str, rate_hz: float) -> list[float]:
    """Skip unless the composed loop fits real time at ``rate_hz`` and the bridge's ``path``
    (``PATH_HOPS``: its two hops and the work between) fits a period with this machine's raw
    hop; the hop measured now (the test measures it again after its run)."""
    require_realtime([SLIDE_LOOP])
    hops = [hop_floor_us()]
    require_path_latency(path, hops[0], rate_hz)
    return hops


def run_session(
    tmp_path: Path, driver: dict[str, object], config: str, sets: list[str]
) -> tuple[Truth, dict[str, float]]:
    """The driver and ``haptic-launch config`` (namespace /haptic) for ``RUN_S`` of the
    bridge's run; the driver's truth and the bridge's counts."""
    sets = [f"bridge_node:duration_s={RUN_S}", *sets]
    extra = list(scheduling.launch_args())
    return bridge_session(ROOT / "config" / config, dict(driver), tmp_path, sets, extra)


def closes(truth: Truth, counts: dict[str, float], rate_hz: float) -> None:
    """Commands for most states, most of them on time at the driver; nothing refused. Skips
    when the test driver itself (Python, beside the loop) did not hold its rate: its own
    premise, which a real driver meets."""
    share = truth.ticked_share()
    if share < DRIVER_SHARE:
        pytest.skip(
            f"the test driver ticked {100 * share:.0f} % of its periods at {rate_hz:g} Hz on "
            f"this machine now (needs {100 * DRIVER_SHARE:.0f} %)"
        )
    handed = counts["handed_on"]
    assert handed >= 0.5 * RUN_S * rate_hz, counts  # the driver may tick late on a busy machine
    assert counts["commands_on_time"] + counts["commands_late"] >= 0.9 * handed, counts
    assert counts["refused_commands"] == 0 and truth.counts["size_errors"] == 0
    c = truth.counts
    assert c["commands_on_time"] > 0.5 * (c["commands_on_time"] + c["commands_late"]), c
    assert c["nonfinite_dropped"] == 0


def rendered(depth: np.ndarray, hand: np.ndarray, stiffness: float) -> float:
    """The median of wall force over hand force where the hand presses into the wall (> 0.5 N,
    > 0.5 mm): 1 when the wall is rendered as stiff as asked (statics)."""
    contact = (depth > 5e-4) & (hand > 0.5)
    assert contact.sum() >= 200, "the hand never pressed into the wall"
    return float(np.median(stiffness * depth[contact] / hand[contact]))


def weight_down(truth: Truth) -> np.ndarray:
    """The simulated Touch's weight at its tip (N, down), per tick: ``J^-T G(q)`` of its
    truth (phantom_omni.urdf with its payload)."""
    plant = truth.info["plant"]
    model = UrdfModel(
        ROOT / "config" / "urdf" / "phantom_omni.urdf", "tip", payload_kg=plant["payload_kg"]
    )
    out = []
    for q in truth.q:
        q = np.asarray(q, dtype=np.float64)
        out.append(np.linalg.solve(model._jacobian(q).T, model._gravity(q))[2])
    return np.array(out)


def test_forcedimension_loop_closes_at_1khz_and_renders_the_wall(tmp_path) -> None:
    """forcedimension_ros2-like: joint_states fd_x, fd_y, fd_z, Float64MultiArray commands; the
    hand pushes +x into the 800 N/m wall at x = 0."""
    hops = premise("fd", 1000.0)
    driver = {"kind": "fd", "rate_hz": 1000.0, "hand": SLIDE_HAND, "hand_direction": [1, 0, 0]}
    truth, counts = run_session(tmp_path, driver, "bridge_forcedimension.yaml", [])
    hops.append(hop_floor_us())
    require_path_latency("fd", max(hops))
    closes(truth, counts, 1000.0)
    ratio = rendered(truth.q[:, 0], truth.hand[:, 0], 800.0)
    assert 0.7 < ratio < 1.3, ratio


def test_touch_loop_closes_at_500hz_and_renders_the_wall(tmp_path) -> None:
    """Touch-like: position-only best-effort joint_states at 500 Hz, a WrenchStamped force in
    the driver's pose frame (the URDF's base frame), applied only while the stylus's white
    button is held (the bridge's dead-man too); the hand pushes down into the 400 N/m floor
    5 mm below the stylus's start."""
    hops = premise("touch", 500.0)
    hand = {**SLIDE_HAND, "offset_m": 0.012}
    driver = {"kind": "touch", "rate_hz": 500.0, "hand": hand, "hand_direction": [0, 0, -1]}
    truth, counts = run_session(tmp_path, driver, "bridge_touch.yaml", [])
    hops.append(hop_floor_us())
    require_path_latency("touch", max(hops), 500.0)
    closes(truth, counts, 500.0)
    depth = -0.0817 - truth.tip[:, 2]  # bridge_touch.yaml's floor
    # the stylus rests on the floor with the hand's push and its weight (nothing compensates it)
    ratio = rendered(depth, -truth.hand[:, 2] + weight_down(truth), 400.0)
    assert 0.7 < ratio < 1.3, ratio
    # the commands before the test's press reached the bridge are gated (that lag is discovery's
    # on this machine, a retry costs 2 s); once held, none: no release, and a command for every
    # state from the first answered one on
    assert counts["deadman_releases"] == 0 and counts["gated_commands"] < 0.5 * counts["handed_on"]
    assert truth.answered_share() >= 0.9, (truth.answered_share(), counts)


def test_arm_as_teleoperation_slave_through_the_bridge(tmp_path) -> None:
    """A Franka-like ros2_control arm (7 joints and a gripper, in a shuffled order; its URDF
    read from the driver's latched robot_description) is the slave of the simulated slide:
    the slave's observer, through the bridge, estimates the table's force on the tool, which
    the master renders."""
    from support.capacity import require_realtime_teleop

    require_realtime_teleop(composed=True)
    hops = [hop_floor_us()]
    require_path_latency("arm", hops[0])
    env = isolated_env()
    stats = tmp_path / "bridge.json"
    drv = start({"kind": "arm", "rate_hz": 1000.0, "table_z": 0.39}, env, tmp_path / "driver")
    estimate = {"wrench_estimate": "geometry_msgs/msg/WrenchStamped"}
    col = Collector(env, estimate, name="estimates", namespace="/slave", back_pressure=False)
    graph = launch(
        str(ROOT / "config" / "bridge_arm_teleop.yaml"),
        env,
        ["slave/bridge_node:duration_s=6.0", f"slave/bridge_node:stats_file={stats}"],
        tmp_path / "launch.log",
        extra=["--robot-description", "/arm/robot_description", *scheduling.priority_args()],
    )
    try:
        assert graph.wait(120) == 0, graph.output()
    finally:
        graph.stop()
        drv.stop()
        time.sleep(0.2)
        col.close()
    truth, counts = Truth.read(tmp_path / "driver"), json.loads(stats.read_text())
    hops.append(hop_floor_us())
    require_path_latency("arm", max(hops))
    est = {
        m.header.stamp.sec * 10**9 + m.header.stamp.nanosec: m.wrench.force.z
        for m in col.messages("wrench_estimate")
    }
    idx = [i for i, s in enumerate(truth.stamps.tolist()) if s in est]
    assert len(idx) >= 1000
    true_z = truth.hand[idx, 2]
    est_z = np.array([est[truth.stamps[i]] for i in idx])
    contact = true_z > 5.0
    assert contact.sum() >= 500, "the slave never pressed on the table"
    err = est_z[contact] - true_z[contact]
    span = true_z[contact].max() - true_z[contact].min()
    rms, bound = float(np.sqrt(np.mean(err**2))), 0.1 * max(span, 10.0)
    c = truth.counts
    on_time = c["commands_on_time"] / max(1, c["commands_on_time"] + c["commands_late"])
    if on_time < ON_TIME:
        pytest.skip(
            f"{100 * on_time:.1f} % of the commands reached the test driver before its next "
            f"state on this machine now (the estimate presumes {100 * ON_TIME:g} %); measured "
            f"anyway: the estimate {rms:.2f} N RMS in contact (bound {bound:.2f} N)"
        )
    closes(truth, counts, 1000.0)  # after the premise: on one CPU beside the arm's own plant
    assert rms < bound, (rms, bound)
