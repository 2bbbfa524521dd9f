"""Safety at the bridge, each item on a forcedimension_ros2-like test driver, whose forward command
controller holds the last command forever: whatever stops, the driver ends up holding zero.

The loop is played by the test (``LoopStandIn``, answering each sample with a chosen command), so
each item is studied alone; waits count the bridge's samples, and the driver's truth is read by
sample stamps (a command answers the state whose stamp it carries).
"""

from __future__ import annotations

import math
import os
import signal
import time

import numpy as np
import pytest
from std_msgs.msg import Bool

from support.drivers.bridge_run import NS, BridgeRun
from support.drivers.run import Controls
from support.drivers.stand_in import LoopStandIn
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess]

PUSH = (1.0, 0.0, 0.0)  # N: what the stand-in asks for
WAIT_S = 120.0  # wall-clock cap of any wait (the waits count samples)


def started(run: BridgeRun, samples: int = 200) -> None:
    """The bridge hands samples on and the stand-in answered ``samples`` of them."""
    assert wait_until(lambda: run.loop.count() >= 1, WAIT_S), run.bridge.output()
    assert run.loop.wait_samples(samples, WAIT_S), run.bridge.output()


def nonzero(values: np.ndarray) -> np.ndarray:
    return np.any(np.abs(values) > 0.0, axis=1)


def test_loop_command_stops_zero_within_the_timeout_in_driver_states(tmp_path) -> None:
    """The controller stops answering: within ``command_timeout_s`` of the driver's states the
    bridge sends zero, and keeps sending it; the driver ends up applying zero."""
    quiet_after = 300
    run = BridgeRun(tmp_path, lambda k: PUSH if k <= quiet_after else None)
    try:
        started(run, quiet_after + 300)
    finally:
        truth = run.finish()
    cmd = truth.commands
    values, answered = cmd[:, 2:], truth.answered
    pushes = np.flatnonzero(nonzero(values))
    assert len(pushes), "no push reached the driver"
    if len(pushes) < quiet_after // 2:  # the premise: the loop pushed before it went quiet
        pytest.skip(
            f"{len(pushes)} of the stand-in's {quiet_after} pushes reached the driver on this "
            "machine now (the test presumes half): "
            f"bridge {run.counts()}, driver {truth.counts}"
        )
    last_push = pushes[-1]
    zeros = np.flatnonzero(~nonzero(values[last_push:])) + last_push
    assert len(zeros), "no zero came after the loop went quiet"
    # the watchdog counts the driver's states from the last push's arrival (a late push still
    # feeds it): its zero answers a state at most timeout + 1 of them after the push reached
    # the driver, which is after the bridge sent it (a few more where the bridge's queue of 10
    # states overflowed on a loaded machine)
    pushed_at = int(np.searchsorted(truth.instants, cmd[last_push, 0]))
    gap = truth.tick_of(answered[zeros[0]]) - pushed_at
    assert gap <= 6 + 4, gap  # command_timeout_s 5 ms at 1 kHz: tripped on the 6th state
    assert not nonzero(values[zeros[0] :]).any()  # zero from then on
    assert truth.info["last_command"] == [0.0, 0.0, 0.0]
    arrived = cmd[zeros[0], 0]
    after = truth.instants > arrived  # ticks taking the zero or after: written at the first
    assert not nonzero(truth.applied[after][1:]).any()
    assert run.counts()["watchdog_trips"] >= 1


def test_driver_state_stops_zero_and_the_stale_state_is_not_rendered(tmp_path) -> None:
    """The driver's state stops (its publisher stalls while its controller still listens): the
    bridge sends zero after ``state.timeout_s``, refuses the loop's late commands for the last
    state, and resumes when the state comes back."""
    # state.timeout_s as BridgeRun sets it (50 ms): 10 ms trips again after the state is back,
    # beside a CPU hog, and each trip drops the answers to the states before it
    run = BridgeRun(tmp_path, lambda k: PUSH)
    controls = Controls(run.env, "/fd")
    try:
        started(run, 300)
        controls.pause(0.5)
        seen = [run.loop.count()]

        def quiet() -> bool:  # no new sample for five looks (100 ms): the pause is on
            seen.append(run.loop.count())
            return len(seen) > 5 and len(set(seen[-6:])) == 1

        assert wait_until(quiet, WAIT_S, poll_s=0.02)
        silent_from = run.loop.newest_stamp()
        t_stale = time.monotonic()
        while time.monotonic() < t_stale + 0.3:  # the loop insists on the stale sample
            run.loop.send(silent_from, PUSH)
            time.sleep(0.01)
        # the state is back (a newer sample): the loop resumes
        assert wait_until(lambda: run.loop.newest_stamp() > silent_from, WAIT_S)
        assert run.loop.wait_samples(300, WAIT_S)
    finally:
        controls.close()
        truth = run.finish()
    paused = truth.paused
    assert paused.sum() >= 100, "the pause did not happen"
    # the premise: the quiet the test saw was the pause (not a stall of this process beside a
    # CPU hog), so that the loop insisted on the state before it for the whole 0.3 s
    after = truth.stamps[truth.published & (truth.stamps > silent_from)]
    gap_s = (after[0] - silent_from) * 1e-9 if len(after) else math.inf
    if gap_s < 0.4:
        pytest.skip(
            f"the loop's quiet was a stall of {gap_s * 1e3:.0f} ms before the pause on this "
            f"machine now (the test presumes the pause, 500 ms): {run.counts()}"
        )
    last = np.flatnonzero(paused)[-1]
    cmd = truth.commands
    # the loop's 30 insisting pushes for the stale sample: none passes (its one answer may)
    stale = (truth.answered == silent_from) & nonzero(cmd[:, 2:])
    assert stale.sum() <= 1, "a stale state was rendered"
    # the driver ends the pause holding zero: the run of zeros its last commands before the
    # pause's end belong to, written at the first tick whose instant is after the run's first
    # came, applied over the periods after that
    taken = np.flatnonzero(cmd[:, 0] < truth.instants[last])
    pushes = taken[nonzero(cmd[taken, 2:])]
    z = int(pushes[-1]) + 1 if len(pushes) else int(taken[0])
    assert z <= taken[-1], "no zero reached the driver while its state was stopped"
    written = np.flatnonzero((truth.instants > cmd[z, 0]) & paused)
    assert len(written) >= 50
    assert not nonzero(truth.applied[written[1:]]).any()
    resumed = truth.commands[truth.commands[:, 0] > truth.times[last]]
    assert nonzero(resumed[:, 2:]).sum() >= 100, "the loop did not resume"
    counts = run.counts()
    assert counts["state_trips"] >= 1 and counts["dropped_commands"] >= 1


def test_deadman_released_zero_at_once(tmp_path) -> None:
    """Force only while the dead-man (a Bool pedal) is held; released: zero at once and no
    command after it passes."""
    run = BridgeRun(
        tmp_path,
        lambda k: PUSH,
        **{"safety.deadman": "bool", "safety.deadman_topic": "/pedal"},
    )
    pedal = run.loop.node.create_publisher(Bool, "/pedal", 10)
    try:
        started(run, 200)
        assert wait_until(lambda: pedal.get_subscription_count() >= 1, WAIT_S)
        t_held = time.monotonic()  # before: a push may arrive before this thread runs again
        pedal.publish(Bool(data=True))
        assert run.loop.wait_samples(300, WAIT_S)
        t_released = time.monotonic()
        pedal.publish(Bool(data=False))
        assert run.loop.wait_samples(300, WAIT_S)
    finally:
        truth = run.finish()
    cmd = truth.commands
    before = cmd[cmd[:, 0] < t_held]
    assert len(before) and not nonzero(before[:, 2:]).any(), "force before the pedal was held"
    held = cmd[(cmd[:, 0] > t_held) & (cmd[:, 0] < t_released)]
    pushed = cmd[nonzero(cmd[:, 2:]), 0]  # arrival of each push
    if nonzero(held[:, 2:]).sum() < 100 and len(pushed) and pushed[0] > t_released - 0.1:
        pytest.skip(  # the premise: the bridge heard the press within the 300 samples held
            f"the first push reached the driver {pushed[0] - t_held:.2f} s after the press, "
            f"{t_released - t_held:.2f} s held, on this machine now: {run.counts()}"
        )
    assert nonzero(held[:, 2:]).sum() >= 100
    after = cmd[cmd[:, 0] > t_released]
    # pushes in flight at the release (a watchdog zero may come between them on a loaded
    # machine), then zero for good
    pushes = np.flatnonzero(nonzero(after[:, 2:]))
    settled = int(pushes[-1]) + 1 if len(pushes) else 0
    assert truth.info["last_command"] == [0.0, 0.0, 0.0]
    counts = run.counts()
    assert counts["deadman_releases"] == 1
    if settled > 100:  # the premise: the bridge heard the release within 100 of its cycles
        pytest.skip(
            f"pushes reached the driver for {settled} commands after the release on this "
            f"machine now (the bridge behind its queues; the test presumes 100): {counts}"
        )
    # the 300 samples after the release leave, behind at most 100 in flight, 150 zeros
    assert len(after) - settled >= 150, "too few commands after the release to tell"


def test_nan_from_the_law_is_never_sent(tmp_path) -> None:
    """A NaN or inf command from the loop is refused and zero goes out: the driver never sees
    a non-finite value (a forward command controller would drop it and keep the last push)."""
    bad_after = 300

    def answer(k: int) -> tuple[float, float, float] | None:  # then silence: the queue drains
        if k <= bad_after:
            return PUSH
        return (math.nan if k % 2 else math.inf, 0.0, 0.0) if k <= 2 * bad_after else None

    run = BridgeRun(tmp_path, answer)
    try:
        started(run, 2 * bad_after + 200)
    finally:
        truth = run.finish()
    assert truth.counts["nonfinite_dropped"] == 0
    values = truth.commands[:, 2:]
    assert np.isfinite(values).all()
    assert nonzero(values).sum() <= bad_after  # no push answers a NaN (nor a clamped NaN)
    last_push = np.flatnonzero(nonzero(values))[-1]
    assert not nonzero(values[last_push + 1 :]).any() and last_push + 1 < len(values)
    assert truth.info["last_command"] == [0.0, 0.0, 0.0]
    counts = run.counts()
    refused, dropped = counts["refused_commands"], counts["dropped_commands"]
    assert refused + dropped >= 250, counts  # every bad answer refused, or dropped unsent
    if refused < 250:  # the premise: the bridge kept up, so that it dropped none as stale
        pytest.skip(
            f"{dropped} of the bad answers were dropped (stale: no state for state.timeout_s, "
            f"or older than the newest answered) on this machine now, {refused} refused: {counts}"
        )


@pytest.mark.parametrize("signum", [signal.SIGTERM, signal.SIGINT], ids=["SIGTERM", "SIGINT"])
def test_orderly_exit_leaves_the_driver_holding_zero(tmp_path, signum: int) -> None:
    """SIGTERM (ros2 launch's shutdown, systemd, haptic-launch) or Ctrl-C while the loop
    pushes: the bridge sends zero before it exits, and the driver holds that zero."""
    run = BridgeRun(tmp_path, lambda k: PUSH)
    try:
        started(run, 300)
        os.killpg(run.bridge.proc.pid, signum)
        assert run.bridge.wait(WAIT_S) == 0, run.bridge.output()
        assert "shutdown: zero command sent to the driver" in run.bridge.output()
        time.sleep(0.2)  # the driver takes the zero and writes it at its next update
    finally:
        truth = run.finish()
    assert truth.info["last_command"] == [0.0, 0.0, 0.0]
    assert nonzero(truth.commands[:, 2:]).sum() >= 50  # it was pushing
    assert not nonzero(truth.applied[-10:]).any()
    assert truth.counts["size_errors"] == 0


def test_the_clamp_and_the_rate_limit(tmp_path) -> None:
    """A command past the clamp reaches the driver clamped per axis, and no element changes by
    more than rate_limit * period between two commands."""
    run = BridgeRun(
        tmp_path,
        lambda k: (40.0, -40.0, 0.5) if (k // 100) % 2 else (0.5, 0.5, 0.5),
        **{"safety.command_limits": [5.0, 3.0, 5.0], "safety.rate_limit": [1000.0]},
    )
    try:
        started(run, 600)
    finally:
        truth = run.finish()
    values = truth.commands[:, 2:]
    assert np.abs(values[:, 0]).max() == pytest.approx(5.0)
    assert np.abs(values[:, 1]).max() == pytest.approx(3.0)
    # a loop command moves at most 1 N from the command of the state before (1000 N/s at 1 kHz),
    # also up from a zero; a zero (the stop's, a watchdog's on a loaded machine) is never slowed.
    # Pairs of commands answering consecutive states: the driver's subscription keeps the last
    # 10 and may drop some on a loaded machine
    ticks = np.array([truth.tick_of(s) for s in truth.answered])
    pairs = (np.diff(ticks) == 1) & nonzero(values[1:])
    assert pairs.sum() >= 50
    assert np.abs(np.diff(values, axis=0))[pairs].max() <= 1.0 + 1e-9
    counts = run.counts()
    assert counts["clamped_commands"] > 100 and counts["rate_limited_commands"] > 10


def test_a_stray_publisher_moves_nothing_through_the_bridge(tmp_path) -> None:
    """Command authority at the bridge: the loop's controller (its commands carry the session's
    token) pushes; a second publisher of effort_command in the same namespace answers the same
    samples with another force, as a stray ros2 topic pub would: it is refused and named once,
    and nothing of its force reaches the driver."""
    stray_push = (2.5, 0.0, 0.0)
    run = BridgeRun(tmp_path, lambda k: PUSH)
    stray = LoopStandIn(run.env, NS, lambda k: stray_push, name="stray_pub")
    try:
        started(run, 300)
        assert stray.wait_samples(300, WAIT_S), run.bridge.output()
    finally:
        stray.close()
        truth = run.finish()
    values = truth.commands[:, 2:]
    assert nonzero(values).sum() >= 100, "the loop did not push"
    assert not np.isclose(values[:, 0], stray_push[0]).any(), "a stray command reached the driver"
    out = run.bridge.output()
    assert out.count(f"refused effort_command from {NS}/stray_pub") == 1, out
