"""Faults in real time: a node killed with SIGKILL stops the force at once; a restart resumes.

The node to kill runs in its own process, the rest of the loop composed in another (started
through the ros2 run contract, not the launcher, so one can be killed): a loop of two processes.
The test measures, on the device's own sample clock, how long after the last command the applied
effort (``joint_states.effort``) reaches zero, reads why from ``/diagnostics``, restarts the node
and sees the force come back. A restarted node that stays deaf to the others while the force stays
zero (Fast DDS's shared memory after a kill -9: 2 in 102 restarts beside a CPU hog;
docs/safety.md) is an xfail that says so when ``heard_nothing`` finds the middleware's signature
and a second instance, started beside the deaf one, closes the loop.
"""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import time

import numpy as np
import pytest

from haptic_dob.bag.joints import read_joint
from haptic_msgs_py.stamps import command_stamp, stamp_ns
from haptic_msgs_py.topics import DIAGNOSTICS, EFFORT_COMMAND, JOINT_STATES, SESSION_TOPICS
from support.capacity import require_realtime
from support.paths import tool
from support.recorded import assert_received_written_in_bag, bag_stamps
from support.rosgraph import Collector, Process, isolated_env, restart, start_nodes, stop_all
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

# the watchdog trips at the first tick after command_timeout_s (the device's default) without a
# command; the zero effort shows in the sample after that tick: at most the timeout + 2 periods
TIMEOUT_S = 0.005
PERIOD_S = 0.001
HELD_ZERO = 300  # samples at zero effort that show the force stays off after a kill


LOOP = ("environment_node", "observer_node", "controller_node", "device_node")


def others(victim: str) -> list[str]:
    """The loop's nodes but ``victim``: they share a process, the victim has its own."""
    return [n for n in LOOP if n != victim]


class Efforts:
    """(receive time, stamp s, effort) of every joint_states ``col`` received so far, each message
    decoded once: decoding them all on every poll grew with the run (20 000 samples: a core of
    this process busy, starving the loop it watches on a loaded machine)."""

    def __init__(self, col: Collector) -> None:
        from haptic_msgs_py.wire import decoder

        self.col = col
        self.decode = decoder(SESSION_TOPICS[JOINT_STATES])
        self.t: list[float] = []
        self.stamp: list[float] = []
        self.effort: list[float] = []

    def __call__(self) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        with self.col._lock:
            new = self.col.records[JOINT_STATES][len(self.t) :]
        for t, b in new:
            m = self.decode(b)
            self.t.append(t)
            self.stamp.append(stamp_ns(m) * 1e-9)
            self.effort.append(m.effort[0])
        return np.array(self.t), np.array(self.stamp), np.array(self.effort)


def last_nonzero_command(col: Collector) -> float:
    """Stamp (s) of the newest effort command with a nonzero effort seen, -1 if none."""
    from haptic_msgs_py.wire import decoder

    decode = decoder(SESSION_TOPICS[EFFORT_COMMAND])
    with col._lock:
        raw = list(col.records[EFFORT_COMMAND])
    best = -1.0
    for _, b in raw:
        m = decode(b)
        stamp = command_stamp(m.layout.dim[0].label) if m.layout.dim else None
        if stamp is not None and m.data[0] != 0.0:
            best = max(best, stamp * 1e-9)
    return best


def diagnostics_after(col: Collector, t0: float) -> list[str]:
    """Status messages published after ``t0`` (test-process monotonic time)."""
    from haptic_msgs_py.wire import decoder

    decode = decoder("diagnostic_msgs/msg/DiagnosticArray")
    with col._lock:
        raw = [b for t, b in col.records[DIAGNOSTICS] if t > t0]
    return [f"{s.name}: {s.message}" for b in raw for s in decode(b).status]


@pytest.mark.parametrize(
    ("victim", "mode", "reason"),
    [
        ("controller_node", "OL", "device_node: watchdog tripped"),
        ("observer_node", "DOB", "controller_node: fallback zero: wrench_estimate"),
        ("environment_node", "OL", "device_node: watchdog tripped"),
    ],
)
def test_kill_9_zeroes_the_force_within_the_command_timeout(
    root, tmp_path, victim, mode, reason
) -> None:
    watched = {
        JOINT_STATES: SESSION_TOPICS[JOINT_STATES],
        DIAGNOSTICS: "diagnostic_msgs/msg/DiagnosticArray",
        EFFORT_COMMAND: SESSION_TOPICS[EFFORT_COMMAND],
    }
    require_realtime([others(victim)], mode, watched=watched)
    env = isolated_env()
    config = root / "config" / "slide_sim.yaml"
    sets = [
        "device_node:clock_mode=realtime",
        "device_node:duration_s=0.0",
        f"controller_node:mode={mode}",
        "controller_node:kf=1.0",
        # a fine encoder and no Coulomb friction (the slide never sticks, so its position never
        # repeats; stuck by stiction it held equal efforts for up to 40 samples): consecutive
        # commands differ, so the run of equal efforts before the zero starts at the first sample
        # that shows the last command the device received
        "device_node:plant.encoder_resolution_m=1.0e-9",
        "device_node:plant.coulomb_n=0.0",
    ]
    col = Collector(env, watched)
    efforts = Efforts(col)
    procs = start_nodes(config, env, sets, tmp_path, groups=[others(victim)])
    try:
        # the loop runs: the hand pushes into the wall, the effort is the wall's push-back

        def pushing() -> bool:
            _, _, e = efforts()
            return bool(e.size > 500 and np.all(np.abs(e[-200:]) > 0.1))

        if not wait_until(pushing, 40, poll_s=0.2):
            pytest.fail("the loop did not close: " + procs["device_node"].output()[-2000:])
        t_kill = time.monotonic()
        os.kill(procs[victim].proc.pid, signal.SIGKILL)
        procs[victim].proc.wait(5)

        # wait until the newest samples show the force held at zero: a fixed sleep is not enough,
        # nor is the newest sample's stamp at the kill a reference (on one loaded core this
        # process may take the samples half a second late, and the device skips the ticks it
        # slept through); bounded in samples of the device
        def zeroed() -> bool:
            _, _, e = efforts()
            return bool(e.size > HELD_ZERO and not np.any(e[-HELD_ZERO:]))

        if not wait_until(zeroed, 20, poll_s=0.2):
            _, _, e = efforts()
            pytest.fail(
                f"the effort did not stay at zero after the kill (the last efforts {e[-5:]}): "
                + procs["device_node"].output()[-1500:]
            )
        t, stamps, e = efforts()
        before = t < t_kill
        after = ~before
        # the force is zero from some sample after the kill to the end (the node stays dead)
        nonzero = np.nonzero(e != 0.0)[0]
        assert nonzero.size and nonzero[-1] < e.size - 1, "the effort never went to zero"
        first_zero = nonzero[-1] + 1
        assert stamps[first_zero] > stamps[before][-1] - 0.1
        # before it, the device held the last command it got until the watchdog or the controller's
        # fallback zeroed it: counted in the device's samples (its ticks, as the watchdog counts
        # them: a loaded machine's overruns stretch the stamps' time, not the count) from the first
        # sample that shows that command. Two lower bounds for that sample: the start of the run of
        # equal efforts (a command can repeat a value while the sender lives), and the sample after
        # the newest nonzero command this test saw (command k shows in sample k + 1; the sender may
        # die before its last commands reach the test). The later one is the closer bound.
        held = 0
        while held + 1 <= nonzero[-1] and e[nonzero[-1] - held - 1] == e[nonzero[-1]]:
            held += 1
        shown = nonzero[-1] - held
        cmd_stamp = last_nonzero_command(col)
        if cmd_stamp > 0.0:
            after_cmd = int(np.searchsorted(stamps, cmd_stamp, side="right"))
            if after_cmd <= nonzero[-1] and e[after_cmd] == e[nonzero[-1]]:
                shown = max(shown, after_cmd)
        latency = first_zero - shown  # samples
        assert latency <= round(TIMEOUT_S / PERIOD_S) + 2, f"{latency} samples"
        # diagnostics come once a second; on one loaded core the collector may take a while to
        # see them (a guard against hanging, not a bound on the node)
        wait_until(lambda: any(reason in s for s in diagnostics_after(col, t_kill)), 30, poll_s=0.2)
        statuses = diagnostics_after(col, t_kill)
        assert any(reason in s for s in statuses), statuses
        # bring the node back: the force comes back
        t_restart = time.monotonic()
        restart(procs, victim, env, tmp_path, config, sets)

        def resumed() -> bool:
            t, _, e = efforts()
            return bool(np.sum(np.abs(e[t > t_restart]) > 0.1) > 200)

        if not wait_until(resumed, 40, poll_s=0.2):
            _, _, e = efforts()
            # the force held at zero all along, and the restarted node deaf: the middleware's
            # fault if a second instance, started beside the deaf one (so on another port),
            # closes the loop; a fault of the suite's would keep that one deaf too
            deaf = "" if np.any(e[-HELD_ZERO:]) else heard_nothing(col, victim, t_restart)
            if deaf:
                deaf_one, t_second = procs[victim], time.monotonic()
                (tmp_path / "second").mkdir()
                restart(procs, victim, env, tmp_path / "second", config, sets)
                second = wait_for_effort(efforts, t_second, 200, 40)
                deaf_one.stop()
                if second:
                    pytest.xfail(f"{deaf}; a second instance beside it closed the loop")
            pytest.fail(
                f"the loop did not resume after restarting {victim} ({e.size} samples, the last "
                f"efforts {e[-5:]}); {victim}: {procs[victim].output()[-1500:]}; the rest: "
                f"{procs['device_node'].output()[-1500:]}"
            )
        # ... and keeps coming (a snapshot of the last samples could fall in a watchdog trip
        # when this loaded machine stalls a process for more than the 5 ms command timeout)
        assert wait_for_effort(efforts, t_restart, 400, 20), (
            f"the loop did not stay closed: {victim}"
        )
        assert after.any()
    finally:
        stop_all(procs)
        col.close()


#: what each victim's cycle needs from the others: the node that publishes it, and the input
INPUTS = {
    "controller_node": ("environment_node", "wrench_desired"),
    "observer_node": ("device_node", "joint_states"),
    "environment_node": ("device_node", "ee_pose"),
}


def heard_nothing(col: Collector, victim: str, since: float) -> str:
    """Why the restarted ``victim`` did not close the loop, when it is the middleware's known
    fault and not the suite's (else ''): alive on DDS (its /diagnostics reach this process), the
    node publishing its input cycling (so publishing it), and yet the victim ran not one cycle in
    20 s. Fast DDS 2.14's shared-memory transport can leave a restarted participant deaf to the
    survivors of a kill -9 whose port it took again (eProsima/Fast-DDS#5053; docs/safety.md)."""
    from haptic_msgs_py.wire import decoder

    decode = decoder("diagnostic_msgs/msg/DiagnosticArray")
    with col._lock:
        diags = [b for t, b in col.records[DIAGNOSTICS] if t > since + 20.0]
    rates: dict[str, list[float]] = {}
    for b in diags:
        for st in decode(b).status:
            for v in st.values:
                if v.key == "loop_rate_hz":
                    rates.setdefault(st.name.lstrip("/"), []).append(float(v.value))
    source, topic = INPUTS[victim]
    mine, theirs = rates.get(victim, []), rates.get(source, [])
    if len(mine) < 5 or any(mine) or len(theirs) < 5 or min(theirs) < 100.0:
        return ""
    return (
        f"the restarted {victim} is on DDS ({len(mine)} reports in its last 20 s) and "
        f"{source} publishes its {topic} ({min(theirs):.0f}-{max(theirs):.0f} Hz), but it ran "
        "no cycle: Fast DDS's shared memory after a kill -9 (eProsima/Fast-DDS#5053; "
        "docs/safety.md)"
    )


def wait_for_effort(efforts: Efforts, since: float, n: int, timeout: float) -> bool:
    """``n`` samples with a pushing effort (> 0.1 N) arrived after ``since`` (monotonic s)."""

    def enough() -> bool:
        t, _, e = efforts()
        return bool(np.sum(np.abs(e[t > since]) > 0.1) >= n)

    return wait_until(enough, timeout, poll_s=0.2)


def test_a_bag_recorded_across_a_node_kill_is_readable_and_analysable(root, tmp_path) -> None:
    """haptic-record runs through kill -9 and restart of the environment node in real time: it
    stops cleanly, wrote what it received, the gap is in the bag, and haptic-analyze reads it.
    How long the device held the last command is the device's own record (its log and
    ``stats_file``), not the recorder's view: on one loaded core the recorder may miss commands
    before the kill, which widens the gap it sees."""
    watched = {JOINT_STATES: SESSION_TOPICS[JOINT_STATES]}
    require_realtime([others("environment_node")], watched=watched)
    env = isolated_env()
    config = root / "config" / "slide_sim.yaml"
    stats = tmp_path / "stats.json"
    sets = [
        "device_node:clock_mode=realtime",
        "device_node:duration_s=0.0",
        f"device_node:stats_file={stats}",
    ]
    bag = tmp_path / "across_kill"
    col = Collector(env, watched)
    efforts = Efforts(col)
    rec = Process([tool("haptic-record"), str(bag)], env, tmp_path / "record.log")
    procs = start_nodes(config, env, sets, tmp_path, groups=[others("environment_node")])
    try:
        assert wait_for_effort(efforts, 0.0, 4000, 60), procs["device_node"].output()[-2000:]
        os.kill(procs["environment_node"].proc.pid, signal.SIGKILL)
        procs["environment_node"].proc.wait(5)
        time.sleep(1.0)
        t_restart = time.monotonic()
        restart(procs, "environment_node", env, tmp_path, config, sets)
        if not wait_for_effort(efforts, t_restart, 4000, 60):
            t, _, e = efforts()
            pytest.fail(
                f"the loop did not resume: {np.sum(np.abs(e[t > t_restart]) > 0.1)} pushing "
                f"samples of {np.sum(t > t_restart)} since the restart; environment_node: "
                f"{procs['environment_node'].output()[-1500:]}; the rest: "
                f"{procs['device_node'].output()[-1500:]}"
            )
        os.killpg(rec.proc.pid, signal.SIGINT)
        assert rec.wait(30) == 0, rec.output()
    finally:
        rec.stop()
        stop_all(procs)
        col.close()
    # the device's own record: its watchdog zeroed the force after holding the last command for
    # the timeout and one sample, each time it tripped (it says so; the stats count the trips)
    device_log = procs["device_node"].output()
    held = re.findall(r"no valid effort_command for (\d+) samples", device_log)
    trip = round(TIMEOUT_S / PERIOD_S) + 1
    assert held and all(int(n) == trip for n in held), device_log[-2000:]
    assert json.loads(stats.read_text())["watchdog_trips"] >= 1
    assert_received_written_in_bag(bag)
    stamps = bag_stamps(bag)
    wall = stamps["/wrench_desired"]
    i = int(np.argmax(np.diff(wall)))
    assert wall[i + 1 :].size > 3000, "the restarted environment node is not in the bag"
    # the device went on through the kill: its samples span the gap of the commands (how many
    # depends on the host, not on the recorder), which the wall force's gap overlaps (the recorder
    # may miss the dying node's last messages, and hear the restarted node after the controller
    # does). What the recorder wrote of the gap ends with the force off until the first command
    # after the kill: the nonzero efforts come first (the held command, and commands the device
    # had that the recorder missed), then zero through the gap's end, over more samples than the
    # watchdog's hold
    commands = stamps["/effort_command"]
    j = int(np.argmax(np.diff(commands)))
    c0, c1 = commands[j], commands[j + 1]
    assert max(wall[i], c0) < min(wall[i + 1], c1), (wall[i : i + 2], commands[j : j + 2])
    joint = read_joint(bag)
    gap = (joint.stamps_ns > c0) & (joint.stamps_ns <= c1)
    effort = joint.effort[gap]
    pushing = np.flatnonzero(effort)
    assert gap.sum() > 2 * trip, f"no gap in the bag across the kill: {gap.sum()} samples"
    zeros = effort.size - (pushing[-1] + 1 if pushing.size else 0)  # the zero run at the end
    assert zeros > 2 * trip, (zeros, effort.size, pushing.size)
    out = subprocess.run(
        [tool("haptic-analyze"), "--json", str(bag)], capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    segments = json.loads(out.stdout)
    assert segments and all(s["controller"] == "OL" for s in segments)
    assert any(
        s["stiffness_n_per_m"] == 800.0 and s["bandwidth_hz"] is not None for s in segments
    ), segments
