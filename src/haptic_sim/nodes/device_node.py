"""device_node: a simulated haptic device on the lab network, in lockstep or in real time.

Publishes per sample k (stamp ``k * T``): ``ee_pose``, ``ee_twist``, ``joint_states`` (position,
velocity, and the effort applied over [k-1, k) after saturation), ``wrench_measured`` (the handle
force sensor), ``sim/hand_wrench`` (the true hand force, for evaluation) and, in lockstep,
``/clock``. Takes ``effort_command`` (Float64MultiArray in joint order).

- lockstep: sample 0 goes out once the nodes in ``wait_for`` are up and matched; sample k+1 only
  after command k (labelled ``effort@<stamp>``, or unlabelled) arrived. If no command comes within
  ``lockstep_timeout_s`` the node says so and sends sample k again (every node answers a repeated
  sample idempotently). While a recorder reports its progress (``recorder/progress``), the device
  also holds the next sample when the recorder lags more than ``max_recorder_lag_s`` of simulated
  time, so a recording of a lockstep run never loses a sample. Stops after ``duration_s``
  (0: never), once a recorder (if any) has written the last sample.
- realtime: once the ``wait_for`` nodes are up (as in lockstep; ``[]`` starts at once), ticks at
  ``rate_hz`` and applies the newest valid command; records whether command k arrived before the
  next tick and its latency (``stats_file``).

Safety (every path, both modes): each joint's effort is clamped to ``effort_limits`` (at most the
actuator's own saturation; changeable at run time); a command of the wrong length or with NaN/inf
is refused and counts as zero effort (counted, logged once per burst); in real time a watchdog
zeroes the effort when no valid command came for ``command_timeout_s`` and says so, and the next
valid command resumes; at shutdown the effort goes to zero first. ``/diagnostics`` reports the
loop rate, deadline misses, the watchdog, refused and limited commands.
"""

from __future__ import annotations

import json
import math
import os
import sys
import time
from collections.abc import Mapping
from typing import Any

from rclpy.context import Context

from haptic_dob.models.factory import model_specs
from haptic_dob.nodes.common import CLOCK_MODES, loop_specs, main_for, process_specs
from haptic_dob.runtime.params import ParamSpec
from haptic_dob.runtime.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.params import ParameterTable
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.ros.raw import raw_subscription
from haptic_msgs_py.stamps import NS_PER_S
from haptic_msgs_py.topics import (
    CLOCK,
    EE_POSE,
    EE_TWIST,
    EFFORT_COMMAND,
    HAND_WRENCH,
    JOINT_STATES,
    RECORDER_PROGRESS,
    WRENCH_MEASURED,
)
from haptic_msgs_py.values import EffortCommand, JointSample, Stamp, StampedVector
from haptic_sim.device import DeviceSample
from haptic_sim.factory import build_device, simulation_specs
from haptic_sim.latency import LatencyHistogram

DEFAULT_WAIT_FOR = ["environment_node", "observer_node", "controller_node"]
STARTUP_RESEND_S = 0.5
DRAIN_TIMEOUT_S = 10.0  # how long a finished run waits for a recorder to write its last sample
RECORDER_STALE_S = 1.0  # a recorder silent this long no longer holds the loop


def device_node_specs() -> list[ParamSpec]:
    """Every parameter of the device node."""
    return [
        ParamSpec(
            "command_timeout_s",
            0.005,
            "realtime watchdog: zero effort when no valid command came for this long of "
            "simulated time (samples: a stall of the device's own process does not count)",
            "s",
            0.0005,
            1.0,
        ),
        ParamSpec(
            "effort_limits",
            [0.0],
            "per-joint effort limit (N or N m) applied to every command, at most the actuator's "
            "saturation; [0.0] = the actuator's saturation",
        ),
        *loop_specs(),
        *process_specs(),
        *model_specs(),
        ParamSpec(
            "clock_mode",
            "lockstep",
            "lockstep: advance when command k arrived; realtime: tick at rate_hz",
            choices=CLOCK_MODES,
            read_only=True,
        ),
        *simulation_specs(),
        ParamSpec(
            "lockstep_timeout_s",
            2.0,
            "lockstep: warn and re-send a sample after this long without its command (a "
            "best-effort input can drop a sample on a loaded machine)",
            "s",
            0.01,
            3600.0,
        ),
        ParamSpec(
            "wait_for",
            list(DEFAULT_WAIT_FOR),
            "nodes (in this namespace) that must be up before sample 0, in both clock modes "
            "(realtime with []: tick at once, the watchdog holds zero effort until commands come)",
            read_only=True,
        ),
        ParamSpec(
            "start_delay_s",
            0.5,
            "settle time between the wait_for graph being up and "
            "sample 0 (endpoint matching between the other nodes)",
            "s",
            0.0,
            60.0,
            read_only=True,
        ),
        ParamSpec(
            "stats_file",
            "",
            "realtime: write cycle statistics (JSON) here at shutdown",
            read_only=True,
        ),
        ParamSpec(
            "max_recorder_lag_s",
            0.5,
            "lockstep: hold the loop while a recorder is this far behind in simulated time",
            "s",
            0.01,
            3600.0,
        ),
    ]


class DeviceNode(LoopNode):
    """A simulated device stepping in the cycle contract."""

    def __init__(self, context: Context | None = None, name: str = "device_node") -> None:
        super().__init__(name, context=context)
        self.params = ParameterTable(self, device_node_specs())
        v = self.params.values
        self.device = build_device(v)
        self.dof = self.device.dof
        self.hardware_limits = tuple(self.device.max_effort)
        self.limits: tuple[float, ...] = self.params.set_validator(self._limits, self._set_limits)
        self.period_ns = self.device.period_ns
        self.lockstep = v["clock_mode"] == "lockstep"
        cycles = round(v["duration_s"] * v["rate_hz"])
        self.last_k = cycles if cycles > 0 else None  # the run ends after publishing sample N
        base = v["base_frame"]
        self._names = tuple(self.device.model.joint_names)

        def pub(topic: str, codec: codecs.Codec, frame: str) -> LoopPublisher:
            return LoopPublisher(self, topic, codec, qos.LOOP, frame)

        self._p_pose, self._p_twist = (
            pub(EE_POSE, codecs.POSE, base),
            pub(EE_TWIST, codecs.TWIST, base),
        )
        self._p_js = pub(JOINT_STATES, codecs.JOINT_STATE, base)
        self._p_measured = pub(WRENCH_MEASURED, codecs.WRENCH, base)
        # evaluation topics: sent only while someone listens
        self._p_hand = LoopPublisher(
            self, HAND_WRENCH, codecs.WRENCH, qos.LOOP, base, on_demand=True
        )
        self._p_clock = (
            LoopPublisher(self, CLOCK, codecs.CLOCK, qos.CLOCK, on_demand=True)
            if self.lockstep
            else None
        )
        self._sub = LoopSubscription(
            self, EFFORT_COMMAND, codecs.EFFORT, self._on_command, qos.LOOP_IN
        )
        self._bus = self._sub.bus
        self._recorder_ns: int | None = None  # newest stamp the slowest recorder has written
        self._recorders: dict[str, tuple[float, int]] = {}  # name -> (wall time, stamp)
        self._drain_until: float | None = None  # after the last sample: wait for the recorder
        self._held: list[float] | None = None  # a command waiting for the recorder
        if self.lockstep:
            raw_subscription(
                self, "std_msgs/msg/Header", RECORDER_PROGRESS, self._on_progress, qos.CLOCK
            )
        self._zero = [0.0] * self.dof
        self._latest = self._zero
        self._last_command_k = -1  # the sample k at which the newest valid command came
        self.refused = 0
        self.limited = 0
        self._refusing = False
        self.watchdog_tripped = False
        self.watchdog_trips = 0
        self._started = False
        self._stepped = False  # lockstep: command k applied, sample k+1 not yet published
        self._ready_since: float | None = None
        self._t_first = 0.0
        self._deadline = time.monotonic() + 0.1
        self._sent_s = 0.0
        # real-time statistics
        self._on_time = 0
        self._late = 0
        self._missed_ticks = 0
        self._latency = LatencyHistogram()  # constant memory however long it runs
        self._command_k = -1
        self.diagnostics = Diagnostics(self, self._report)
        mode = "lockstep" if self.lockstep else f"realtime at {v['rate_hz']:g} Hz"
        self.get_logger().info(
            f"simulated {v['model']} device, {mode}, effort limits {list(self.limits)}, "
            f"scheduling {scheduling()}"
        )

    # --- parameters -------------------------------------------------------------------------
    def _limits(self, values: Mapping[str, Any]) -> tuple[float, ...]:
        """The per-joint limits a set of values asks for (ValueError with the reason if refused)."""
        asked = list(values["effort_limits"])
        if asked == [0.0]:
            return self.hardware_limits
        if len(asked) != self.dof:
            raise ValueError(f"effort_limits needs {self.dof} values (one per joint), got {asked}")
        for i, (a, hw) in enumerate(zip(asked, self.hardware_limits, strict=True)):
            if not 0.0 < a <= hw:
                raise ValueError(
                    f"effort_limits[{i}] must be in (0, {hw:g}] (actuator saturation), got {a}"
                )
        return tuple(float(a) for a in asked)

    def _set_limits(self, limits: tuple[float, ...]) -> None:
        self.limits = limits
        self.get_logger().info(f"effort limits now {list(limits)}")

    # --- publishing ------------------------------------------------------------------------
    def _publish(self, s: DeviceSample) -> None:
        """Sample k to every topic, in the order that closes the loop soonest: the wall's inputs
        first. Nodes in this process get it at once, depth first: the sensor before the joints,
        so that in CL the command is out before the observer works. A device alone in its
        process sends the joints before the sensor: each DDS send costs tens of microseconds
        and in DOB (the suite's subject) the observer's joints are on the command's path.
        Readers in other processes get the sample once it is all out (``Bus.batch``)."""
        self._sent_s = time.monotonic()
        k = s.stamp_ns
        bus = self._bus
        bus.begin()
        try:
            self._p_pose.publish(StampedVector(k, s.ee_position))
            self._p_twist.publish(StampedVector(k, s.ee_velocity))
            measured = StampedVector(k, s.wrench_measured)
            if bus.composed:
                self._p_measured.publish(measured)
            self._p_js.publish(JointSample(k, self._names, s.q, s.qd, s.effort))
            if not bus.composed:
                self._p_measured.publish(measured)
            # evaluation-only topics: built only when someone takes them
            if self._p_hand.wanted:
                self._p_hand.publish(StampedVector(k, s.hand_force))
            if self._p_clock is not None and self._p_clock.wanted:
                self._p_clock.publish(Stamp(k))
        finally:
            bus.end()

    # --- commands --------------------------------------------------------------------------
    def _checked(self, data: tuple[float, ...]) -> list[float] | None:
        """The command clamped to the limits, or None when it is refused (wrong length, NaN)."""
        if len(data) != self.dof or not all(map(math.isfinite, data)):
            self.refused += 1
            if not self._refusing:
                self.get_logger().warning(
                    f"refusing effort_command {list(data)!r}: need {self.dof} finite values; "
                    "zero effort until a valid command"
                )
                self._refusing = True
            return None
        self._refusing = False
        out = list(data)
        limited = False
        for i, (e, lim) in enumerate(zip(data, self.limits, strict=True)):
            if e > lim or e < -lim:
                out[i] = lim if e > 0 else -lim
                limited = True
        if limited:
            self.limited += 1
        return out

    def _on_command(self, cmd: EffortCommand) -> None:
        stamp = cmd.stamp_ns
        current = self.device.k * self.period_ns
        if self.lockstep:
            if not self._started or (stamp is not None and stamp != current):
                return  # stale, duplicate, or before the run started
            if self._drain_until is not None or self._stepped:
                return  # the run is over, or command k already moved the plant
            effort = self._checked(cmd.effort)
            if effort is None:
                effort = self._zero  # a refused command is zero effort; the loop goes on
            if self._recorder_lags():
                self._held = effort  # the recorder's progress callback releases it
                return
            self._advance(effort)
            return
        effort = self._checked(cmd.effort)
        if effort is None:
            self._latest = self._zero
            return
        now = time.monotonic()
        self._latest = effort
        self._last_command_k = self.device.k
        if self.watchdog_tripped:
            self.watchdog_tripped = False
            self.get_logger().info(
                "valid effort_command again: effort resumed", throttle_duration_sec=1.0
            )
        if stamp == current and self.device.k != self._command_k:
            self._command_k = self.device.k
            self._on_time += 1
            self._latency.add(now - self._sent_s)
            self._bus.call_soon(self.device.prepare)  # the loop is idle until the next tick

    def _on_progress(self, msg: Any) -> None:
        st = msg.stamp
        now = time.monotonic()
        reports = self._recorders
        reports[msg.frame_id] = (now, st.sec * NS_PER_S + st.nanosec)
        # follow the slowest recorder that still reports (each sends at least 20 times a second)
        self._recorder_ns = min(ns for t, ns in reports.values() if t >= now - RECORDER_STALE_S)
        if self._drain_until is not None:
            self._check_drained()
            return
        if self._held is not None and not self._recorder_lags():
            effort, self._held = self._held, None
            self._advance(effort)

    def _recorder_lags(self) -> bool:
        """A recorder is connected and more than ``max_recorder_lag_s`` behind sample k."""
        if self._recorder_ns is None:
            return False
        lead = self.device.k * self.period_ns - self._recorder_ns
        return lead > self.params.values["max_recorder_lag_s"] * NS_PER_S

    def _advance(self, effort: list[float]) -> None:
        """Command k reaches the plant: held over [k, k+1), the device steps to sample k+1.

        In lockstep sample k+1 goes out once this cycle's publishes have returned (at once when
        the command came from another process).
        """
        self.device.apply(effort)
        if self.lockstep:
            self._stepped = True
            self._bus.call_soon(self._send_sample)

    def _send_sample(self) -> None:
        """Publish the current sample; in lockstep arm the re-send and end the run at its end."""
        self._stepped = False
        s = self.device.sample()
        last = self.last_k is not None and s.k >= self.last_k and self._drain_until is None
        if last:  # the run ends with this sample: a command that answers it moves nothing
            self._drain_until = time.monotonic() + DRAIN_TIMEOUT_S
        self._publish(s)
        self.diagnostics.tick()
        if self.lockstep:
            self.device.prepare()  # while the others work on sample k
            self._deadline = self._sent_s + self.params.values["lockstep_timeout_s"]
        if last:
            wall = time.monotonic() - self._t_first
            sim = s.k * self.period_ns * 1e-9
            self.get_logger().info(
                f"finished: {s.k} cycles ({sim:g} s simulated) in {wall:.2f} s, "
                f"real-time factor {sim / wall:.2f}"
            )
            # stay up (publishers alive) until a recorder has written the last sample
            self._deadline = time.monotonic()
            self._check_drained()

    def _check_drained(self) -> None:
        """Finish once no recorder reports, or it has written the last sample (or time is up)."""
        last_ns = self.device.k * self.period_ns
        if self.count_publishers(RECORDER_PROGRESS) == 0 or (
            self._recorder_ns is not None and self._recorder_ns >= last_ns
        ):
            self.finished = True
        elif self._drain_until is not None and time.monotonic() >= self._drain_until:
            self.get_logger().warning(
                f"the recorder has not written the last sample after {DRAIN_TIMEOUT_S:g} s; "
                "stopping anyway"
            )
            self.finished = True

    # --- time ------------------------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        return self._deadline

    def on_wakeup(self, now: float) -> None:
        if self._drain_until is not None:  # the run is over: wait for the recorder
            self._check_drained()
            self._deadline = now + 0.05
            return
        if not self._started and self._ready_since is None:
            if self._graph_ready():
                self._ready_since = now
                if self.lockstep or self.params.values["wait_for"]:
                    self._deadline = now + self.params.values["start_delay_s"]
                    return
            else:
                self._deadline = now + 0.05
                return
        if not self.lockstep:
            self._tick(now)
            return
        if not self._started:
            self._started = True
            self._t_first = now
            self._publish(self.device.sample())
            self._deadline = now + STARTUP_RESEND_S
            return
        k = self.device.k
        if self._held is not None:  # waiting for the recorder, not for a command
            if self.count_publishers(RECORDER_PROGRESS) == 0:  # the recorder is gone: go on
                self.get_logger().warning("the recorder stopped reporting; the loop goes on")
                self._recorder_ns = None
                effort, self._held = self._held, None
                self._advance(effort)
                return
            self._deadline = now + self.params.values["lockstep_timeout_s"]
            self.get_logger().warning(
                "holding the loop: the recorder is "
                f"{(k * self.period_ns - (self._recorder_ns or 0)) * 1e-9:.2f} s behind",
                throttle_duration_sec=5.0,
            )
            return
        if self._stepped:  # sample k+1 is on its way (deferred work not run yet)
            self._deadline = now + self.params.values["lockstep_timeout_s"]
            return
        if k == 0:
            self._publish(self.device.sample())  # start-up: a late subscriber may have missed it
            self._deadline = now + STARTUP_RESEND_S
            return
        self.get_logger().warning(
            f"no {EFFORT_COMMAND} for cycle {k} (stamp {k * self.period_ns * 1e-9:.3f} s) within "
            f"{self.params.values['lockstep_timeout_s']:g} s; is controller_node running and "
            "receiving its inputs? Sending the sample again."
        )
        self._publish(self.device.sample())
        self._deadline = now + self.params.values["lockstep_timeout_s"]

    def _graph_ready(self) -> bool:
        """Every ``wait_for`` node is up, known subscribers matched, a command publisher seen.

        While not, says what it waits for (every 5 s), so a device that does not start says why.
        """
        waiting = self._waiting_for()
        if waiting:
            self.get_logger().info(
                f"waiting before sample 0 for {waiting} (wait_for: "
                f"{list(self.params.values['wait_for'])})",
                throttle_duration_sec=5.0,
            )
        return not waiting

    def _waiting_for(self) -> str:
        """What the start still waits for ('' when nothing)."""
        wait_for = self.params.values["wait_for"]
        ns = self.get_namespace()
        names = {n for n, space in self.get_node_names_and_namespaces() if space == ns}
        missing = [w for w in wait_for if w not in names]
        if missing:
            return f"node{'s' if len(missing) > 1 else ''} {', '.join(missing)} in {ns}"
        for pub in self._bus.publishers():  # this node's and any composed with it
            if pub.readers < self.count_subscribers(pub.topic):
                return f"the subscribers of {pub.topic} to match"
        if wait_for and self._sub.get_publisher_count() < 1:
            return f"a publisher of {EFFORT_COMMAND}"
        return ""

    def _tick(self, now: float) -> None:
        period = self.period_ns * 1e-9
        if not self._started:
            self._started = True
            self._t_first = now
            self._publish(self.device.sample())
            self._deadline = now + period
            return
        if self._command_k != self.device.k and self._on_time:
            self._late += 1  # counted once the loop has closed (the first command came)
        effort = self._latest
        if self._watchdog_due():
            effort = self._zero
        self._advance(effort)
        self._send_sample()
        self._deadline += period
        if now - self._deadline > period:  # fell behind by more than a period: resynchronise
            self._missed_ticks += int((now - self._deadline) / period)
            self._deadline = now + period

    def _watchdog_due(self) -> bool:
        """No valid command for ``command_timeout_s`` of simulated time (samples): trip, say so
        once. The simulated plant moves only when the device ticks, so a stall of this process
        (the host, the garbage collector) never trips it, while a silent controller trips it
        within the timeout of the plant's time however late or bunched the ticks come."""
        silent = self.device.k - self._last_command_k  # periods the newest command was held
        timeout = self.params.values["command_timeout_s"]
        if silent * self.period_ns <= timeout * NS_PER_S:
            return False
        if not self.watchdog_tripped:
            self.watchdog_tripped = True
            self.watchdog_trips += 1
            held = "ever" if self._last_command_k < 0 else f"{silent} samples"
            self.get_logger().warning(
                f"watchdog: no valid {EFFORT_COMMAND} for {held} (limit {timeout * 1e3:g} ms of "
                f"simulated time): effort zeroed ({self.watchdog_trips} trips so far)",
                throttle_duration_sec=1.0,
            )
        return True

    # --- end -------------------------------------------------------------------------------
    def stats(self) -> dict[str, Any]:
        """Real-time cycle statistics so far."""
        total = self._on_time + self._late
        return {
            "cycles": self.device.k,
            "commands_on_time": self._on_time,
            "commands_late": self._late,
            "on_time_pct": 100.0 * self._on_time / total if total else math.nan,
            "missed_ticks": self._missed_ticks,
            "latency_p50_ms": self._latency.percentile(50) * 1e3,
            "latency_p99_ms": self._latency.percentile(99) * 1e3,
            "refused_commands": self.refused,
            "limited_commands": self.limited,
            "watchdog_trips": self.watchdog_trips,
        }

    def _report(self) -> Report:
        values: dict[str, Any] = {
            "clock_mode": "lockstep" if self.lockstep else "realtime",
            "cycle": self.device.k,
            "watchdog": "tripped: effort zeroed" if self.watchdog_tripped else "ok",
            "watchdog_trips": self.watchdog_trips,
            "refused_commands": self.refused,
            "limited_commands": self.limited,
            "effort_limits": list(self.limits),
        }
        if not self.lockstep:
            values.update(
                deadline_misses=self._missed_ticks,
                late_commands=self._late,
                on_time_commands=self._on_time,
            )
        if self.watchdog_tripped:
            return WARN, "watchdog tripped: no valid effort_command, effort zeroed", values
        if self._refusing:
            return WARN, "refusing invalid effort_command (zero effort)", values
        if not self._started:
            return OK, "waiting for the graph", values
        return OK, "running", values

    def on_shutdown(self) -> None:
        """Zero effort first; in real time one last period runs and is reported with it."""
        path = self.params.values["stats_file"]
        if path and not self.lockstep:
            with open(path, "w", encoding="utf-8") as fh:
                json.dump(self.stats(), fh, indent=2)
        self._latest = self._zero
        if not self.lockstep and self._started:
            self._advance(self._zero)
            self._send_sample()
        self.get_logger().info("shutdown: effort zeroed")


def scheduling() -> str:
    """This process's CPU scheduling: ``SCHED_FIFO priority 50`` or ``normal``."""
    if hasattr(os, "sched_getscheduler") and os.sched_getscheduler(0) == os.SCHED_FIFO:
        return f"SCHED_FIFO priority {os.sched_getparam(0).sched_priority}"
    return "normal"


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_sim device_node``."""
    return main_for(DeviceNode, args)


if __name__ == "__main__":
    sys.exit(main())
