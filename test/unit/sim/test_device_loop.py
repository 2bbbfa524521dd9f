"""The device's loop without ROS: watchdog, real-time statistics, recorder gate and the cycle."""

from __future__ import annotations

import json
import math
from collections import deque
from collections.abc import Callable
from dataclasses import asdict
from typing import Any

import pytest

from haptic_dob.core.watchdog import CommandWatchdog
from haptic_msgs_py.values import EffortCommand
from haptic_sim.device.cycle_stats import RealtimeStats
from haptic_sim.device.factory import build_device
from haptic_sim.device.loop import STARTUP_RESEND_S, DeviceLoop
from haptic_sim.device.recorder_gate import Drain, RecorderGate
from haptic_sim.device.report import device_status
from haptic_sim.device.sample import DeviceSample
from haptic_sim.device.settings import device_node_specs

PERIOD_NS = 1_000_000


# --- watchdog --------------------------------------------------------------------------------
def test_the_watchdog_trips_after_the_timeout_in_samples_once_and_resumes() -> None:
    said: list[str] = []
    resumed: list[bool] = []
    dog = CommandWatchdog(PERIOD_NS, said.append, lambda: resumed.append(True))
    assert not dog.due(4, 0.005) and not said  # 5 samples since "before sample 0"
    assert dog.due(5, 0.005) and said == ["ever"] and dog.trips == 1  # no command yet
    dog.fed(5)
    assert resumed == [True] and not dog.tripped
    for k in range(5, 11):  # held for 5 samples (the timeout), the 6th is one too many
        assert not dog.due(k, 0.005)
    assert dog.due(11, 0.005) and dog.due(12, 0.005)
    assert said == ["ever", "6 samples"] and dog.trips == 2 and dog.tripped
    dog.fed(12)
    assert not dog.due(12, 0.005) and resumed == [True, True]


# --- real-time statistics --------------------------------------------------------------------
def test_commands_on_time_are_counted_once_per_sample_and_late_ones_after_the_first() -> None:
    stats = RealtimeStats()
    stats.tick(0)  # before the first command: not late (the loop has not closed)
    assert stats.late == 0
    assert stats.command(1, 0.0002) and not stats.command(1, 0.0003)  # a duplicate of command 1
    stats.tick(1)
    stats.tick(2)  # command 2 never came
    assert (stats.on_time, stats.late) == (1, 1)
    result = stats.result(cycles=3, refused=4, limited=5, watchdog_trips=6)
    assert result.on_time_pct == 50.0 and result.latency_p50_ms == pytest.approx(0.201)
    assert (result.refused_commands, result.limited_commands, result.watchdog_trips) == (4, 5, 6)


def test_the_statistics_keep_the_stats_file_keys_and_are_nan_before_a_command() -> None:
    result = RealtimeStats().result(0, 0, 0, 0)
    assert list(asdict(result)) == [
        "cycles",
        "commands_on_time",
        "commands_late",
        "on_time_pct",
        "missed_ticks",
        "overruns",
        "latency_p50_ms",
        "latency_p99_ms",
        "refused_commands",
        "limited_commands",
        "watchdog_trips",
    ]
    assert math.isnan(result.on_time_pct) and math.isnan(result.latency_p99_ms)
    json.dumps(asdict(result))  # what the node writes


def test_a_tick_a_period_late_is_an_overrun_and_the_grid_points_it_passed_are_missed() -> None:
    stats = RealtimeStats()
    assert stats.tick_at(0, 0.00105, 0.001) == 1  # on time
    assert stats.tick_at(1, 0.0029, 0.001) == 2  # late, but within the period: no overrun
    assert (stats.overruns, stats.missed_ticks) == (0, 0)
    assert stats.tick_at(2, 0.0055, 0.001) == 5  # a period and more late: points 3 and 4 passed
    assert (stats.overruns, stats.missed_ticks) == (1, 2)
    assert stats.tick_at(5, 0.0049, 0.001) == 6  # never before the next point


# --- recorder gate ---------------------------------------------------------------------------
def test_the_gate_follows_the_slowest_recorder_that_still_reports() -> None:
    gate = RecorderGate(stale_s=1.0)
    assert not gate.lags(10**9, 0.5)  # no recorder: never
    gate.report("/slow", 100_000_000, now=0.0)
    gate.report("/fast", 900_000_000, now=0.5)
    assert gate.written_ns == 100_000_000 and gate.lags(700_000_000, 0.5)
    assert gate.behind_s(700_000_000) == pytest.approx(0.6)
    gate.report("/fast", 950_000_000, now=1.2)  # /slow silent for more than 1 s: ignored
    assert gate.written_ns == 950_000_000 and not gate.lags(700_000_000, 0.5)


def test_a_held_command_is_released_once_the_recorder_caught_up_or_went() -> None:
    gate = RecorderGate()
    gate.report("/rec", 0, now=0.0)
    gate.hold([1.0])
    assert gate.release(600_000_000, 0.5) is None and gate.held == [1.0]
    gate.report("/rec", 200_000_000, now=0.1)
    assert gate.release(600_000_000, 0.5) == [1.0] and gate.held is None
    gate.hold([2.0])
    gate.let_go()
    assert gate.held is None and gate.written_ns is None and not gate.lags(10**10, 0.5)


def test_the_end_of_a_run_waits_for_the_last_sample_to_be_written() -> None:
    gate = RecorderGate(drain_timeout_s=10.0)
    assert not gate.draining
    gate.start_drain(now=5.0)
    assert gate.draining
    assert gate.drain(last_ns=3_000_000, recorders=0, now=5.0) is Drain.DONE  # nobody records
    gate.report("/rec", 2_000_000, now=5.0)
    assert gate.drain(3_000_000, recorders=1, now=6.0) is Drain.WAITING
    assert gate.drain(3_000_000, recorders=1, now=15.0) is Drain.TIMED_OUT
    gate.report("/rec", 3_000_000, now=6.0)
    assert gate.drain(3_000_000, recorders=1, now=6.0) is Drain.DONE


# --- the cycle -------------------------------------------------------------------------------
class Port:
    """The node's side of the loop, recorded; deferred work waits for ``run_soon``."""

    def __init__(self) -> None:
        self.sent: list[DeviceSample] = []
        self.soon: deque[Callable[[], None]] = deque()
        self.waiting = ""
        self.recorder_count = 0
        self.cycles = 0
        self.finished = False

    def publish(self, sample: DeviceSample) -> None:
        self.sent.append(sample)

    def call_soon(self, work: Callable[[], None]) -> None:
        self.soon.append(work)

    def run_soon(self) -> None:
        while self.soon:
            self.soon.popleft()()

    def waiting_for(self) -> str:
        return self.waiting

    def recorders(self) -> int:
        return self.recorder_count

    def cycled(self) -> None:
        self.cycles += 1

    def finish(self) -> None:
        self.finished = True


class Log:
    """What the loop says, as (level, message)."""

    def __init__(self) -> None:
        self.lines: list[tuple[str, str]] = []

    def info(self, message: str, **_kwargs: Any) -> None:
        self.lines.append(("info", message))

    def warning(self, message: str, **_kwargs: Any) -> None:
        self.lines.append(("warning", message))

    def said(self, text: str) -> int:
        return sum(text in message for _, message in self.lines)


def values(**changes: Any) -> dict[str, Any]:
    """The device node's default parameter values with ``changes``."""
    v: dict[str, Any] = {s.name: s.default for s in device_node_specs()}
    return {**v, **changes}


class Clock:
    """A system clock that the test sets (ns)."""

    def __init__(self, now_ns: int = 1_790_000_000_123_456_789) -> None:
        self.now_ns = now_ns

    def __call__(self) -> int:
        return self.now_ns


def make_loop(
    lockstep: bool, last_k: int | None = None, clock: Clock | None = None, **changes: Any
) -> tuple[DeviceLoop, Port, Log]:
    v = values(**changes)
    port, log = Port(), Log()
    loop = DeviceLoop(build_device(v), port, log, v, lockstep, last_k, clock or Clock())
    return loop, port, log


def started(lockstep: bool, last_k: int | None = None, clock: Clock | None = None, **changes: Any):
    """A loop whose graph is up and which has sent sample 0."""
    loop, port, log = make_loop(lockstep, last_k, clock, **changes)
    loop.wakeup(0.0)  # the graph is up: settle for start_delay_s (none in real time alone)
    if not loop.started:
        loop.wakeup(loop.deadline)
    assert loop.started and [s.k for s in port.sent] == [0]
    return loop, port, log


def command(loop: DeviceLoop, effort: float, stamped: bool = True) -> None:
    """A command labelled with the current sample's stamp (or unlabelled)."""
    stamp = (
        (loop.device.k * loop.period_ns if loop.lockstep else loop.stamp_ns) if stamped else None
    )
    loop.command(EffortCommand(stamp, (effort,)))


def test_what_appears_during_the_settle_time_is_waited_for_too() -> None:
    """A recorder's node shows before its subscriptions do: after the settle time the graph is
    checked again, and sample 0 waits for them to match (the loop's topics are volatile)."""
    loop, port, _log = make_loop(lockstep=True)
    loop.wakeup(1.0)
    assert loop.deadline == pytest.approx(1.5) and not port.sent  # settling
    port.waiting = "the subscribers of /joint_states to match"
    loop.wakeup(1.5)
    assert not loop.started and not port.sent and loop.deadline == pytest.approx(1.55)
    port.waiting = ""
    loop.wakeup(2.0)
    assert not port.sent and loop.deadline == pytest.approx(2.5)  # settles again
    loop.wakeup(2.5)
    assert loop.started and [s.k for s in port.sent] == [0]


def test_sample_0_waits_for_the_graph_and_the_settle_time() -> None:
    loop, port, log = make_loop(lockstep=True)
    port.waiting = "node controller_node in /"
    loop.wakeup(1.0)
    assert loop.deadline == pytest.approx(1.05) and not port.sent
    assert log.said("waiting before sample 0 for node controller_node in / (wait_for: [") == 1
    port.waiting = ""
    loop.wakeup(2.0)
    assert loop.deadline == pytest.approx(2.5) and not port.sent  # start_delay_s
    loop.wakeup(2.5)
    assert loop.started and port.sent[0].k == 0
    assert loop.deadline == pytest.approx(2.5 + STARTUP_RESEND_S)
    loop.wakeup(3.0)  # command 0 did not come: sample 0 again for a late subscriber
    assert [s.k for s in port.sent] == [0, 0] and not log.said("no effort_command")


def test_lockstep_command_k_moves_the_plant_once_and_sample_k_plus_1_follows() -> None:
    loop, port, _log = started(lockstep=True)
    command(loop, 9.0, stamped=False)  # unlabelled: the newest; clipped to the 4 N saturation
    assert loop.device.k == 1 and loop.stepped and len(port.soon) == 1  # sample 1 deferred
    command(loop, 1.0)  # command 0 already moved the plant
    loop.command(EffortCommand(0, (1.0,)))  # stale
    port.run_soon()
    assert [s.k for s in port.sent] == [0, 1] and port.sent[1].effort == (4.0,)
    assert loop.guard.limited == 1 and port.cycles == 1
    assert loop.deadline == pytest.approx(loop.sent_s + 2.0)  # lockstep_timeout_s


def test_lockstep_refused_command_is_zero_effort_and_silence_gets_the_sample_again() -> None:
    loop, port, log = started(lockstep=True)
    command(loop, math.nan)
    port.run_soon()
    assert port.sent[-1].effort == (0.0,) and loop.guard.refused == 1
    assert log.said("refusing effort_command [nan]: need 1 finite values") == 1
    loop.wakeup(loop.deadline)
    assert [s.k for s in port.sent] == [0, 1, 1]
    assert log.said("no effort_command for cycle 1 (stamp 0.001 s) within 2 s") == 1


def test_lockstep_holds_a_command_while_the_recorder_lags_and_goes_on_when_it_is_gone() -> None:
    loop, port, log = started(lockstep=True)
    loop.progress("/rec", 0)
    for _ in range(501):
        command(loop, 0.5)
        port.run_soon()
    assert loop.device.k == 501
    command(loop, 0.5)  # 0.501 s ahead of the recorder: held
    assert loop.device.k == 501 and loop.recorders.held == [0.5]
    port.recorder_count = 1
    loop.wakeup(loop.deadline)
    assert log.said("holding the loop: the recorder is 0.50 s behind") == 1
    port.recorder_count = 0
    loop.wakeup(loop.deadline)
    assert log.said("the recorder stopped reporting; the loop goes on") == 1
    assert loop.device.k == 502 and loop.recorders.held is None


def test_lockstep_run_ends_after_the_last_sample_once_written() -> None:
    loop, port, log = started(lockstep=True, last_k=2)
    port.recorder_count = 1
    loop.progress("/rec", 0)
    for _ in range(2):
        command(loop, 0.1)
        port.run_soon()
    assert [s.k for s in port.sent] == [0, 1, 2] and log.said("finished: 2 cycles") == 1
    assert loop.recorders.draining and not port.finished
    command(loop, 0.1)  # the run is over: nothing moves
    assert loop.device.k == 2 and not port.soon
    loop.progress("/rec", 2 * loop.period_ns)
    assert port.finished


def test_realtime_ticks_apply_the_newest_command_and_the_watchdog_zeroes_a_silence() -> None:
    loop, port, log = started(lockstep=False, wait_for=[])
    t = loop.deadline
    command(loop, 1.5)
    assert loop.realtime.on_time == 1 and len(port.soon) == 1  # device.prepare, deferred
    for _ in range(6):  # command 0 held over the 5-sample timeout
        loop.tick(t)
        t += 0.001
        assert port.sent[-1].effort == (1.5,) and not loop.watchdog.tripped
    sent_at_trip: list[int] = []  # samples out when the trip is said: after the tick's own
    warning = log.warning
    log.warning = lambda m, **kw: (sent_at_trip.append(len(port.sent)), warning(m, **kw))  # type: ignore[method-assign]
    before = len(port.sent)
    loop.tick(t)
    assert port.sent[-1].effort == (0.0,) and loop.watchdog.tripped
    assert log.said("watchdog: no valid effort_command for 6 samples (limit 5 ms") == 1
    assert sent_at_trip == [before + 1]
    command(loop, -1.0, stamped=False)
    loop.tick(t + 0.001)
    assert port.sent[-1].effort == (-1.0,) and not loop.watchdog.tripped
    stats = loop.stats()
    assert stats.cycles == 8 and stats.commands_on_time == 1 and stats.watchdog_trips == 1
    assert stats.commands_late == 7  # every tick after the first had no stamped command
    # said at most a line a second: the resumption waits for the second to pass
    assert log.said("effort resumed") == 0
    loop.tick(t + 1.0)
    assert log.said("valid effort_command again: effort resumed (after trip 1)") == 1


def test_a_trip_soon_after_another_is_said_late_not_lost() -> None:
    """A start-up trip (no command yet), then the link is lost within the second: the second
    trip, with how long its command was held, is said once the second has passed."""
    loop, _port, log = started(lockstep=False, wait_for=[])
    t = loop.deadline
    for _ in range(6):  # no command ever: trips on the sixth sample
        said_at = t
        loop.tick(t)
        t += 0.001
    assert log.said("watchdog: no valid effort_command for ever") == 1
    command(loop, 1.0)
    for _ in range(7):  # resumes, then the command is held 6 samples and the watchdog trips again
        loop.tick(t)
        t += 0.001
    assert loop.watchdog.trips == 2 and len(log.lines) == 1  # within the second: not said yet
    loop.tick(said_at + 0.999)
    assert len(log.lines) == 1
    loop.tick(said_at + 1.0)
    assert log.lines[1] == (
        "warning",
        "watchdog: no valid effort_command for 6 samples (limit 5 ms of samples sent): effort "
        "zeroed (2 trips so far)",
    )
    command(loop, 1.0)
    loop.shutdown()  # the news of the last moment is said, however soon after the line before
    assert log.lines[2] == ("info", "valid effort_command again: effort resumed (after trip 2)")


def test_realtime_follows_the_wall_clock_and_a_late_tick_does_not_slow_time() -> None:
    """Each sample carries the system clock when it was taken; a tick 3.4 periods late is one
    overrun and three missed ticks (4, 5, 6), the plant steps one period with the held command,
    and the next tick is due on the grid again. The watchdog counts the samples sent, so the
    device's own stall does not trip it. A run of N periods ends at grid point N, however many
    ticks were missed."""
    clock = Clock()
    loop, port, log = started(lockstep=False, last_k=9, clock=clock, wait_for=[])
    t0, stamp0 = loop.t_first, clock.now_ns
    assert port.sent[0].stamp_ns == stamp0 == loop.stamp_ns
    t = t0 + 0.001
    for k in range(1, 4):  # on time, the system clock a little after each grid point
        command(loop, 1.0)
        clock.now_ns = stamp0 + k * 1_000_000 + 70_000
        loop.wakeup(t)
        assert port.sent[-1].k == k and port.sent[-1].stamp_ns == clock.now_ns
        t = loop.deadline
        assert t == pytest.approx(t0 + (k + 1) * 0.001)
    command(loop, 2.0)  # command 3, then the device's process stalls
    clock.now_ns = stamp0 + 7_400_000
    loop.wakeup(t0 + 0.0074)
    s = port.sent[-1]
    assert (s.k, s.stamp_ns, s.effort) == (4, clock.now_ns, (2.0,))
    assert loop.grid == 7 and loop.deadline == pytest.approx(t0 + 0.008)
    stats = loop.stats()
    assert (stats.overruns, stats.missed_ticks, stats.cycles, stats.watchdog_trips) == (1, 3, 4, 0)
    assert stats.commands_on_time == 4 and stats.commands_late == 0
    command(loop, 3.0)  # labelled with the newest sample's stamp: on time
    assert loop.realtime.on_time == 5
    for grid in (8, 9):  # the run of 9 periods ends at grid point 9, sample 6
        clock.now_ns = stamp0 + grid * 1_000_000 + 50_000
        loop.wakeup(loop.deadline)
    assert port.sent[-1].k == 6 and loop.recorders.draining
    assert log.said("finished: 6 cycles (0.006 s simulated)") == 1
    assert log.said("3 ticks missed in 1 overruns") == 1


def test_realtime_shutdown_runs_one_last_period_at_zero_effort() -> None:
    loop, port, _log = started(lockstep=False, wait_for=[])
    command(loop, 2.0)
    loop.shutdown()
    assert port.sent[-1].k == 1 and port.sent[-1].effort == (0.0,)


def test_settings_are_checked_against_the_actuator_and_taken_at_once() -> None:
    loop, _port, _log = make_loop(lockstep=True)
    with pytest.raises(ValueError, match=r"effort_limits\[0\] must be in \(0, 4\]"):
        loop.settings_for(values(effort_limits=[5.0]))
    loop.configure(loop.settings_for(values(effort_limits=[1.0], command_timeout_s=0.01)))
    assert loop.guard.limits == (1.0,) and loop.settings.command_timeout_s == 0.01


def test_wait_for_names_a_node_here_or_anywhere_by_its_full_name() -> None:
    """A plain ``wait_for`` name is a node of the device's namespace; ``/rosbag2_recorder``
    (``ros2 bag record``'s node, in the root namespace) waits for a recorder of a namespaced
    session."""
    from haptic_dob.nodes.common import missing_nodes

    graph = [("controller_node", "/slide1"), ("rosbag2_recorder", "/"), ("probe", "/lab/a")]
    wait_for = ["controller_node", "/rosbag2_recorder", "/lab/a/probe"]
    assert missing_nodes(wait_for, graph, "/slide1") == []
    assert missing_nodes(wait_for, graph, "/") == ["controller_node"]
    assert missing_nodes(["rosbag2_recorder", "/slide1/controller_node"], graph, "/slide1") == [
        "rosbag2_recorder"
    ]
    assert missing_nodes(["/rosbag2_recorder"], graph[:1], "/slide1") == ["/rosbag2_recorder"]


def test_start_with_names_devices_fully_qualified_and_waits_for_their_joint_states() -> None:
    """``start_with``: a device to start the clock with counts as built once its
    ``joint_states`` publisher is up; a name that is not fully qualified is refused."""
    from haptic_sim.device.settings import start_topics

    assert start_topics(["/slave/device_node", "/a/b/dev"]) == [
        "/slave/joint_states",
        "/a/b/joint_states",
    ]
    assert start_topics(["/device_node"]) == ["/joint_states"]
    for bad in ("slave/device_node", "device_node", "/slave/"):
        with pytest.raises(ValueError, match="fully qualified"):
            start_topics([bad])


# --- what the node reports ---------------------------------------------------------------------
def test_the_status_warns_of_the_worst_first_and_asks_of_foreign_commands_only_then() -> None:
    loop, _port, _log = make_loop(lockstep=True)
    asked: list[bool] = []

    def foreign() -> bool:
        asked.append(True)
        return True

    status = device_status(loop, {"command_authority": "controller_node"}, foreign)
    assert status.warning and "publishers other than the loop's" in status.message
    assert status.values["clock_mode"] == "lockstep" and "overruns" not in status.values
    assert status.values["command_authority"] == "controller_node" and asked == [True]
    loop, _port, _log = started(lockstep=True)
    command(loop, math.nan)
    status = device_status(loop, {}, foreign)
    assert status.message == "refusing invalid effort_command (zero effort)"
    assert asked == [True]  # the foreign commands' news waits for the next report
    loop, _port, _log = started(lockstep=False, wait_for=[])
    status = device_status(loop, {}, lambda: False)
    assert not status.warning and status.message == "running" and status.values["overruns"] == 0


def test_the_stats_file_holds_the_statistics_nan_before_a_command(tmp_path: Any) -> None:
    path = tmp_path / "stats.json"
    RealtimeStats().result(0, 0, 0, 0).write(str(path))
    written = json.loads(path.read_text())
    assert next(iter(written)) == "cycles" and math.isnan(written["on_time_pct"])
