"""The bridge's cycle without ROS: state k to the loop, command k to the driver, and every way
out of it zero (the watchdogs, the dead-man, refused commands, the stop)."""

from __future__ import annotations

import json
import math
from pathlib import Path

import pytest

from haptic_dob.bridge.answers import ARRIVALS_KEPT
from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.loop import BridgeLoop
from haptic_dob.bridge.report import bridge_status, write_stats
from haptic_dob.bridge.settings import SafetySettings
from haptic_dob.bridge.state import DriverState
from haptic_dob.bridge.timeline import DriverClock
from haptic_dob.core.models.point_mass import PointMassModel
from haptic_msgs_py.values import EffortCommand

FD = ("fd_x", "fd_y", "fd_z")
T = 1_000_000  # ns: 1 kHz


def model() -> PointMassModel:
    return PointMassModel(0.2, 1.5, 0.1)  # a Force Dimension handle (J = I)


def bridge(delay: int = 0, **safety: object) -> BridgeLoop:
    driver = DriverSettings.of(
        {"state.topic": "s", "command.topic": "c", "command.delay_samples": delay}
    )
    s = SafetySettings(**{"command_limits": [5.0], "rate_limit": [0.0], **safety})  # type: ignore[arg-type]
    return BridgeLoop(driver, s.check(), model(), FD, 1000.0)


def state(k: int, x: float = 0.0) -> DriverState:
    return DriverState(k * T, (x, 0.0, 0.0), (0.0, 0.0, 0.0), None)


def cmd(k: int | None, *effort: float) -> EffortCommand:
    return EffortCommand(None if k is None else k * T, effort or (1.0, 0.0, 0.0))


def timing(b: BridgeLoop) -> tuple[float, float]:
    """The commands on time and late so far (the counts book the command taken last)."""
    c = b.counts()
    return c["commands_on_time"], c["commands_late"]


def test_zero_until_the_loop_is_up_then_sample_and_command_at_once() -> None:
    b = bridge()
    sample, zero = b.on_state(state(1), 0.0)
    assert sample is None and zero is not None and zero.values == (0.0, 0.0, 0.0)
    assert b.on_command(cmd(1), 0.0) is None  # not handed on: dropped
    b.start()
    sample, zero = b.on_state(state(2, 0.01), 0.001)
    assert zero is None and sample is not None
    assert sample.stamp_ns == 2 * T and sample.ee_position == pytest.approx((0.01, 0.0, 0.0))
    send = b.on_command(cmd(2, 2.0, -1.0, 9.0), 0.0012)
    assert send is not None and send.values == (2.0, -1.0, 5.0) and send.stamp_ns == 2 * T
    assert b.limiter.clamped == 1 and timing(b) == (1, 0)


@pytest.mark.parametrize("delay", [0, 1])
def test_the_effort_of_k_minus_1_to_k_is_what_was_in_force(delay: int) -> None:
    """Delay 0: the newest command sent before state k came; 1 (ros2_control): the one before."""
    b = bridge(delay)
    b.start()
    efforts = []
    for k in range(1, 5):
        sample, _ = b.on_state(state(k), k * 1e-3)
        assert sample is not None
        efforts.append(sample.effort[0])
        b.on_command(cmd(k, float(k), 0.0, 0.0), k * 1e-3)
    assert efforts == ([0.0, 1.0, 2.0, 3.0] if delay == 0 else [0.0, 0.0, 1.0, 2.0])


def test_the_command_watchdog_counts_driver_states() -> None:
    b = bridge(command_timeout_s=0.003)
    b.start()
    b.on_state(state(1), 0.0)
    assert b.on_command(cmd(1), 0.0) is not None
    zeros = [b.on_state(state(k), 0.0)[1] for k in range(2, 7)]
    assert [z is not None for z in zeros] == [False, False, False, True, True]  # > 3 ms
    assert zeros[-1] is not None and zeros[-1].zero_because == "no loop command"
    assert b.watchdog.trips == 1
    assert b.on_command(cmd(6), 0.0) is not None  # the loop again: the command passes
    assert b.on_state(state(7), 0.0)[1] is None


def test_a_stale_state_is_not_rendered() -> None:
    b = bridge()
    b.start()
    b.on_state(state(1), 0.0)
    assert b.on_wakeup(0.005) is None  # within state.timeout_s (10 ms)
    zero = b.on_wakeup(0.011)
    assert zero is not None and zero.zero_because == "no driver state" and b.state_trips == 1
    assert b.on_command(cmd(1), 0.012) is None  # the command for the stale state: dropped
    assert b.on_wakeup(0.015) is None and b.on_wakeup(0.022) is not None  # zero again
    b.on_state(state(2), 0.03)
    assert not b.state_stale and b.on_command(cmd(2), 0.03) is not None


def test_the_deadman_gates_every_command() -> None:
    b = bridge(deadman="bool", deadman_topic="/pedal")
    b.start()
    _, zero = b.on_state(state(1), 0.0)
    assert zero is not None and zero.zero_because == "dead-man released"  # never seen: released
    assert b.on_command(cmd(1), 0.0) is None and b.gated == 1
    assert b.on_deadman(True, 0.0) is None
    b.on_state(state(2), 0.0)
    assert b.on_command(cmd(2), 0.0) is not None
    zero = b.on_deadman(False, 0.0)
    assert zero is not None and zero.values == (0.0, 0.0, 0.0) and b.deadman_releases == 1


def test_nan_and_the_wrong_length_are_refused_and_send_zero_stale_ones_are_dropped() -> None:
    b = bridge()
    b.start()
    b.on_state(state(1), 0.0)
    b.on_state(state(2), 0.0)
    for bad in (cmd(2, math.nan, 0.0, 0.0), cmd(2, math.inf, 0.0, 0.0), cmd(2, 1.0, 2.0)):
        send = b.on_command(bad, 0.0)
        assert send is not None and send.values == (0.0, 0.0, 0.0)
    assert b.refused == 3
    assert b.on_command(cmd(2), 0.0) is not None
    assert b.on_command(cmd(1), 0.0) is None  # older than the newest answered
    assert b.on_command(cmd(2), 0.0) is None  # answered already
    assert b.on_command(cmd(3), 0.0) is None  # a sample not handed on
    assert b.dropped == 3
    b.on_state(state(3), 0.0)
    assert b.on_command(cmd(None), 0.0) is not None  # unlabelled: the newest


def test_a_state_whose_stamp_did_not_advance_is_not_a_new_state_and_the_stop_is_zero() -> None:
    b = bridge()
    b.start()
    b.on_state(state(2), 0.0)
    assert b.on_state(state(2), 0.0) == (None, None)
    assert b.on_state(state(1), 0.0) == (None, None)
    stop = b.stop(0.0)
    assert stop.values == (0.0, 0.0, 0.0) and stop.zero_because == "stopping"
    assert b.on_state(state(3), 0.0) == (None, None) and b.on_command(cmd(2), 0.0) is None


@pytest.mark.parametrize("delay", [0, 1])
def test_a_command_sent_after_the_drivers_next_instant_is_late_and_not_in_force_there(
    delay: int,
) -> None:
    """States 1-4 heard 50 us after their stamps, each answered (k/2 N) 100 us later; then this
    process is held up: state 5 is heard 1.2 ms late and answered, state 6 waited in the queue
    behind it. Command 5 went out after state 6's instant: late, and not in force over [5, 6)
    (delay 0) nor [6, 7) (delay 1, written at the cycle of state 6)."""
    b = bridge(delay)
    b.start()
    efforts = {}
    for k in range(1, 5):
        efforts[k] = b.on_state(state(k), k * 1e-3 + 50e-6)[0].effort[0]  # type: ignore[union-attr]
        b.on_command(cmd(k, k / 2, 0.0, 0.0), k * 1e-3 + 150e-6)
    assert timing(b) == (4, 0)
    efforts[5] = b.on_state(state(5), 6.2e-3)[0].effort[0]  # type: ignore[union-attr]
    assert b.on_command(cmd(5, 2.5, 0.0, 0.0), 6.3e-3) is not None  # late, but sent
    efforts[6] = b.on_state(state(6), 6.35e-3)[0].effort[0]  # type: ignore[union-attr]
    b.on_command(cmd(6, 3.0, 0.0, 0.0), 6.4e-3)  # on time for state 7's instant (7.05 ms)
    efforts[7] = b.on_state(state(7), 7.05e-3)[0].effort[0]  # type: ignore[union-attr]
    assert timing(b) == (5, 1)
    efforts[8] = b.on_state(state(8), 8.05e-3)[0].effort[0]  # type: ignore[union-attr]
    if delay == 0:  # the newest sent before state k's instant
        assert [efforts[k] for k in range(5, 9)] == [2.0, 2.0, 3.0, 3.0]
    else:  # the newest sent before state k-1's instant
        assert [efforts[k] for k in range(5, 9)] == [1.5, 2.0, 2.0, 3.0]


@pytest.mark.parametrize("system", [False, True])
def test_the_drivers_clock_may_be_another_one(system: bool) -> None:
    """Stamps on a clock 1000 s off this one, the least delay 40 us: instants on this clock,
    the earliest the states could be heard (told the system clock or not)."""
    clock = DriverClock(1e-3)
    off = 1000 * 1_000_000_000
    for k, extra in enumerate([0.3e-3, 40e-6, 0.1e-3, 5e-3]):
        now = 2.0 + k * 1e-3 + extra
        at = clock.heard(off + k * T, now, round(now * 1e9) if system else None)
    assert at == pytest.approx(2.0 + 3e-3 + 40e-6) and math.isnan(clock.age_s)
    later = clock.heard(off + 10 * T, 2.02, 2_020_000_000 if system else None)
    assert later == pytest.approx(2.0 + 10e-3 + 40e-6)


def test_on_one_clock_a_states_instant_is_its_stamp() -> None:
    """The driver stamps on this machine's clock (system = monotonic + 5 s), states heard 200 us
    after their stamps at the least: a state's instant is its stamp. A command sent 100 us after
    the next instant, before that state could be heard, is late and in force a cycle later
    (delay 0); one sent 50 us before it is on time."""
    b = bridge(0)
    b.start()
    system_ns = 5_000_000_000

    def heard(k: int, now: float) -> float:
        sample = b.on_state(state(k), now, round(now * 1e9) + system_ns)[0]
        assert sample is not None
        return sample.effort[0]

    for k in range(1, 4):  # stamps k ms - 5 s on this monotonic clock
        heard(k, k * 1e-3 - 5.0 + 200e-6 + (k == 2) * 300e-6)
    assert b.clock.age_s == pytest.approx(200e-6)
    t3 = 3e-3 - 5.0  # state 3's instant
    b.on_command(cmd(3, 1.0, 0.0, 0.0), t3 + 1e-3 + 100e-6)  # after state 4's instant
    assert heard(4, t3 + 1e-3 + 200e-6) == 0.0  # not in force over [3, 4)
    b.on_command(cmd(4, 2.0, 0.0, 0.0), t3 + 2e-3 - 50e-6)  # before state 5's
    assert heard(5, t3 + 2e-3 + 200e-6) == 2.0
    assert timing(b) == (1, 1) and b.counts()["state_age_ms"] == pytest.approx(0.2)


def test_one_clock_is_told_by_an_age_under_a_period_and_then_kept() -> None:
    """A driver 5 ms behind this clock at 1 kHz (its states' least age 5.04 ms): not one clock,
    instants the earliest the states could be heard. One stamping on this clock (least age
    40 us) is, and stays so when every state of a later stretch arrives 3 ms old."""
    behind, here = DriverClock(1e-3), DriverClock(1e-3)
    for k in range(3):
        now = 2.0 + k * 1e-3 + 40e-6
        now_ns = round(now * 1e9)
        at = behind.heard(now_ns - 5_000_000 - 40_000, now, now_ns)
        assert at == pytest.approx(now)
        at = here.heard(now_ns - 40_000, now, now_ns)
        assert at == pytest.approx(now - 40e-6)
    assert math.isnan(behind.age_s) and here.age_s == pytest.approx(40e-6)
    for k in range(3, 3 + 2 * DriverClock.BLOCK):
        now = 2.0 + k * 1e-3 + 3e-3
        assert here.heard(round((now - 3e-3) * 1e9), now, round(now * 1e9)) == pytest.approx(
            now - 3e-3
        )
    assert here.one_clock and here.age_s == pytest.approx(3e-3)


def test_late_commands_are_counted_per_state() -> None:
    b = bridge()
    b.start()
    b.on_state(state(1), 0.0)
    b.on_command(cmd(1), 0.0)
    b.on_state(state(2), 0.001)
    b.on_state(state(3), 0.002)  # state 2 got no command before state 3
    assert b.on_command(cmd(2), 0.0025) is not None  # late, still newer than the last answered
    assert timing(b) == (1, 1)
    assert b.counts()["on_time_pct"] == pytest.approx(50.0)


def test_states_whose_stamps_do_not_advance_are_said_once_and_counted() -> None:
    said: list[str] = []
    driver = DriverSettings.of({"state.topic": "s", "command.topic": "c"})
    safety = SafetySettings(command_limits=[5.0]).check()
    b = BridgeLoop(driver, safety, model(), FD, 1000.0, said.append)
    b.start()
    b.on_state(state(0), 0.0)  # a driver that leaves its stamps at zero
    for _ in range(3):
        assert b.on_state(state(0), 0.0) == (None, None)
    assert b.counts()["states_not_advancing"] == 3
    assert len([s for s in said if "do not advance" in s]) == 1


def test_the_status_says_why_the_driver_gets_zero_before_asking_of_foreign_commands() -> None:
    b = bridge()
    asked: list[bool] = []

    def foreign() -> bool:
        asked.append(True)
        return True

    status = bridge_status(b, {"command_authority": "controller_node"}, foreign)
    assert status.warning and status.message == "waiting for the loop: zero command"
    assert status.values["command_authority"] == "controller_node" and not asked
    assert status.values["on_time_pct"] == "nan" and status.values["states"] == 0
    b.start()
    b.on_state(state(1), 0.0)
    b.on_command(cmd(1), 0.0)
    status = bridge_status(b, {}, foreign)
    assert status.message == "refused commands from a publisher not the loop's" and asked
    assert not bridge_status(b, {}, lambda: False).warning


def test_the_stats_file_writes_nothing_measured_as_null(tmp_path: Path) -> None:
    path = tmp_path / "stats.json"
    write_stats(str(path), bridge().counts())
    written = json.loads(path.read_text())
    assert written["on_time_pct"] is None and written["states"] == 0


def test_a_late_commands_latency_counts_from_its_own_states_arrival() -> None:
    """The latency is every taken command's, from the arrival of the state it answers: one
    answering a state no longer the newest is timed too, from that state."""
    b = bridge()
    b.start()
    b.on_state(state(1), 0.0)
    b.on_command(cmd(1), 0.0002)  # 0.2 ms, on time
    b.on_state(state(2), 0.001)
    b.on_state(state(3), 0.002)
    assert b.on_command(cmd(2), 0.0045) is not None  # 3.5 ms after state 2 arrived
    b.book()
    assert b.timing.latency.n == 2
    assert b.counts()["latency_p99_ms"] == pytest.approx(3.501, abs=2e-3)
    assert b.counts()["latency_p50_ms"] == pytest.approx(0.201, abs=2e-3)
    for k in range(4, 4 + ARRIVALS_KEPT):  # state 3's arrival is no longer kept
        b.on_state(state(k), k * 1e-3)
    assert b.on_command(cmd(3), 0.040) is not None  # timed from the oldest kept (state 4)
    b.book()
    assert b.timing.latency.n == 3 and b.counts()["latency_p99_ms"] == pytest.approx(
        36.001, abs=2e-3
    )


def test_a_command_is_counted_after_its_send_not_before() -> None:
    """``on_command`` hands the command out without counting or timing it; ``book`` (the node
    calls it after the send), the next state or the counts book it, with the timing taken when
    it came, against the state it answered."""
    b = bridge()
    b.start()
    b.on_state(state(1), 0.0)
    assert b.on_command(cmd(1), 0.0002) is not None
    assert (b.timing.on_time, b.timing.late, b.timing.latency.n) == (
        0,
        0,
        0,
    )  # nothing on the command's path
    b.book()
    assert (b.timing.on_time, b.timing.late, b.timing.latency.n) == (1, 0, 1)
    b.book()  # booked once
    assert (b.timing.on_time, b.timing.latency.n) == (1, 1)
    b.on_state(state(2), 0.001)
    assert b.on_command(cmd(2), 0.0025) is not None  # 1.5 ms: late for state 3's instant
    b.on_state(state(3), 0.0026)  # the next state books it, against state 2's deadline
    assert timing(b) == (1, 1) and b.timing.latency.n == 2
    assert b.counts()["latency_p99_ms"] == pytest.approx(1.501, abs=2e-3)


def test_a_force_command_takes_the_jacobian_made_for_its_states_sample() -> None:
    """On a Cartesian driver ``J^-T`` maps the command with the Jacobian made for the newest
    state's sample: the command's path makes none of its own."""
    driver = DriverSettings.of(
        {"profile": "cartesian_wrench", "state.topic": "s", "command.topic": "c"}
    )
    s = SafetySettings(**{"command_limits": [5.0], "rate_limit": [0.0]})  # type: ignore[arg-type]
    m, made = model(), []
    jacobian = m._jacobian
    m._jacobian = lambda q: (made.append(tuple(q)), jacobian(q))[1]  # type: ignore[method-assign]
    b = BridgeLoop(driver, s.check(), m, FD, 1000.0)
    b.start()
    made.clear()
    b.on_state(state(1, 0.01), 0.0)
    assert (0.01, 0.0, 0.0) in made  # the sample's (ee_twist)
    made.clear()
    send = b.on_command(cmd(1, 2.0, -1.0, 0.5), 0.0002)
    assert send is not None and send.values == pytest.approx((2.0, -1.0, 0.5))
    assert made == []
