"""The simulated device's cycle, ROS-free: when sample k goes out and which command moves the plant.

Sample 0 goes out once the graph is up and settled (``StartGate``). Then:

- lockstep: sample k+1 only after command k came (labelled with sample k's stamp, or
  unlabelled); without it for ``lockstep_timeout_s`` the loop sends sample k again. While a
  recorder lags (``RecorderGate``) command k is held.
- realtime: ticks on the wall clock's grid (sample 0's time plus whole periods), applies the
  newest valid command, steps the plant one period, stamps the sample with the system clock. A
  tick a period late is an overrun; the grid points it passed are lost (docs/running.md, "Clock
  modes"). ``CommandWatchdog`` zeroes the effort when commands stop; ``RealtimeStats`` counts.

Every command passes the ``CommandGuard`` first; ``CommandNews`` says what the loop has to say
of the commands; ``LoopPort``, the node, does what the loop says."""

from __future__ import annotations

import dataclasses
import time
from collections.abc import Callable, Mapping
from typing import Any

from haptic_dob.core.command_guard import CommandGuard
from haptic_dob.core.watchdog import CommandWatchdog
from haptic_msgs_py.topics import EFFORT_COMMAND
from haptic_msgs_py.values import EffortCommand
from haptic_sim.device.command_news import CommandNews
from haptic_sim.device.cycle_stats import CycleStats, RealtimeStats
from haptic_sim.device.factory import SimulatedDeviceKind
from haptic_sim.device.port import Log, LoopPort
from haptic_sim.device.recorder_gate import Drain, RecorderGate
from haptic_sim.device.sample import DeviceSample
from haptic_sim.device.settings import DeviceLoopSettings
from haptic_sim.device.start_gate import GRAPH_POLL_S, StartGate

STARTUP_RESEND_S = 0.5  # lockstep: sample 0 again this often until command 0 comes


class DeviceLoop:
    """One simulated device in the cycle contract, in lockstep or in real time.

    Args:
        device: the simulated device (its sample k is the loop's cycle).
        port: the node's topics, deferred work and graph.
        log: where the loop says what it does.
        values: the node's parameter values (``settings_for``; ``ValueError`` when refused).
        lockstep: lockstep (True) or real time.
        last_k: the run ends after publishing this sample (in real time: the sample of this grid
            point; None: never).
        clock_ns: the system clock that stamps a real-time sample (ns).
    """

    def __init__(
        self,
        device: SimulatedDeviceKind,
        port: LoopPort,
        log: Log,
        values: Mapping[str, Any],
        lockstep: bool,
        last_k: int | None,
        clock_ns: Callable[[], int] = time.time_ns,
    ) -> None:
        self.device = device
        self.clock_ns = clock_ns
        self.port = port
        self.log = log
        self.lockstep = lockstep
        self.last_k = last_k
        self.period_ns = device.period_ns
        self.news = CommandNews(log, device.dof)
        self.guard = CommandGuard(device.max_effort, self.news.refusing)
        self.configure(self.settings_for(values))
        self.watchdog = CommandWatchdog(self.period_ns, self._tripped, self._resumed)
        self.realtime = RealtimeStats()
        self.recorders = RecorderGate()
        self.start_gate = StartGate(port, self.recorders, log)  # when sample 0 goes out
        self.zero = [0.0] * device.dof
        self.latest = self.zero  # realtime: the newest valid command
        self.started = False
        self.stepped = False  # lockstep: command k applied, sample k+1 not yet published
        self.t_first = 0.0  # monotonic s of sample 0
        self.grid = 0  # real time: the wall-clock period of the newest tick since sample 0
        self.ticks = 0  # real time: samples sent after sample 0 (the watchdog's count)
        self.stamp_ns = 0  # the stamp of the newest sample sent
        self.deadline = time.monotonic() + 0.1  # monotonic s of the next wake-up
        self.sent_s = 0.0  # monotonic s the newest sample went out

    def settings_for(self, values: Mapping[str, Any]) -> DeviceLoopSettings:
        """The settings parameter values ask for; ``ValueError`` with the reason when refused
        (``effort_limits`` of another length or beyond the actuator's saturation)."""
        return DeviceLoopSettings.of(values, self.guard.limits_for(values["effort_limits"]))

    def configure(self, settings: DeviceLoopSettings) -> None:
        """Take new settings: the next command is clipped to their limits."""
        self.settings = settings
        self.guard.limits = settings.effort_limits

    # --- the watchdog's news (said once the tick's sample is out) -------------------------
    def _tripped(self, held: str) -> None:
        self.news.tripped(held, self.settings.command_timeout_s, self.watchdog.trips)

    def _resumed(self) -> None:
        self.news.resumed(self.watchdog.trips)

    # --- inputs ---------------------------------------------------------------------------
    def command(self, cmd: EffortCommand) -> None:
        """An effort command arrived (labelled with its sample's stamp, or unlabelled)."""
        stamp = cmd.stamp_ns
        k = self.device.k
        current = k * self.period_ns
        if self.lockstep:
            if not self.started or (stamp is not None and stamp != current):
                return  # stale, duplicate, or before the run started
            if self.recorders.draining or self.stepped:
                return  # the run is over, or command k already moved the plant
            effort = self.guard.check(cmd.effort)
            if effort is None:
                effort = self.zero  # a refused command is zero effort; the loop goes on
            if self.recorders.lags(current, self.settings.max_recorder_lag_s):
                self.recorders.hold(effort)  # the recorder's progress releases it
                return
            self.advance(effort)
            return
        effort = self.guard.check(cmd.effort)
        if effort is None:
            self.latest = self.zero
            return
        now = time.monotonic()
        self.latest = effort
        self.watchdog.fed(self.ticks)
        if stamp == self.stamp_ns and self.realtime.command(k, now - self.sent_s):
            self.port.call_soon(self.device.prepare)  # the loop is idle until the next tick

    def progress(self, recorder: str, written_ns: int) -> None:
        """Recorder ``recorder`` has written the samples up to stamp ``written_ns``."""
        self.recorders.report(recorder, written_ns, time.monotonic())
        if self.recorders.draining:
            self.check_drained()
            return
        k_ns = self.device.k * self.period_ns
        effort = self.recorders.release(k_ns, self.settings.max_recorder_lag_s)
        if effort is not None:
            self.advance(effort)

    # --- the plant and the samples ----------------------------------------------------------
    def advance(self, effort: list[float]) -> None:
        """Command k reaches the plant: held over [k, k+1), the device steps to sample k+1.

        In lockstep sample k+1 goes out once this cycle's publishes have returned (at once when
        the command came from another process).
        """
        self.device.apply(effort)
        if self.lockstep:
            self.stepped = True
            self.port.call_soon(self.send_sample)

    def publish(self, sample: DeviceSample) -> None:
        """Sample k to every topic (its send time starts the command's latency); in real time
        stamped with the system clock as it is taken."""
        if not self.lockstep:
            sample = dataclasses.replace(sample, stamp_ns=self.clock_ns())
        self.stamp_ns = sample.stamp_ns
        self.sent_s = time.monotonic()
        self.port.publish(sample)

    def send_sample(self) -> None:
        """Publish the current sample; in lockstep arm the re-send and end the run at its end."""
        self.stepped = False
        s = self.device.sample()
        at = s.k if self.lockstep else self.grid  # real time: the run lasts its periods
        last = self.last_k is not None and at >= self.last_k and not self.recorders.draining
        if last:  # the run ends with this sample: a command that answers it moves nothing
            self.recorders.start_drain(time.monotonic())
        self.publish(s)
        self.port.cycled()
        if self.lockstep:
            self.device.prepare()  # while the others work on sample k
            self.deadline = self.sent_s + self.settings.lockstep_timeout_s
        if last:
            wall = time.monotonic() - self.t_first
            sim = s.k * self.period_ns * 1e-9
            rt = self.realtime
            missed = f"; {rt.missed_ticks} ticks missed in {rt.overruns} overruns"
            self.log.info(
                f"finished: {s.k} cycles ({sim:g} s simulated) in {wall:.2f} s, "
                f"real-time factor {sim / wall:.2f}{'' if self.lockstep else missed}"
            )
            # stay up (publishers alive) until a recorder has written the last sample
            self.deadline = time.monotonic()
            self.check_drained()

    def check_drained(self) -> None:
        """Finish once no recorder reports, or it has written the last sample (or time is up)."""
        drain = self.recorders.drain(self.stamp_ns, self.port.recorders(), time.monotonic())
        if drain is Drain.TIMED_OUT:
            self.log.warning(
                "the recorder has not written the last sample after "
                f"{self.recorders.drain_timeout_s:g} s; stopping anyway"
            )
        if drain is not Drain.WAITING:
            self.port.finish()

    # --- time -----------------------------------------------------------------------------
    def wakeup(self, now: float) -> None:
        """Called at or after ``deadline`` (monotonic ``now``, s)."""
        if self.recorders.draining:  # the run is over: wait for the recorder
            self.check_drained()
            self.deadline = now + GRAPH_POLL_S
            return
        if not self.started:
            settle = self.lockstep or bool(self.settings.wait_for)
            look_again = self.start_gate.wait(now, self.settings, settle)
            if look_again is not None:
                self.deadline = look_again
                return
        if not self.lockstep:
            self.tick(now)
        elif not self.started:
            self.started = True
            self.t_first = now
            self.publish(self.device.sample())
            self.deadline = now + STARTUP_RESEND_S
        else:
            self.lockstep_timeout(now)

    def lockstep_timeout(self, now: float) -> None:
        """Lockstep, no command moved the plant in time: hold for the recorder, or send again."""
        k = self.device.k
        timeout_s = self.settings.lockstep_timeout_s
        held = self.recorders.held
        if held is not None:  # waiting for the recorder, not for a command
            if self.port.recorders() == 0:  # the recorder is gone: go on
                self.log.warning("the recorder stopped reporting; the loop goes on")
                self.recorders.let_go()
                self.advance(held)
                return
            self.deadline = now + timeout_s
            self.log.warning(
                "holding the loop: the recorder is "
                f"{self.recorders.behind_s(k * self.period_ns):.2f} s behind",
                throttle_duration_sec=5.0,
            )
            return
        if self.stepped:  # sample k+1 is on its way (deferred work not run yet)
            self.deadline = now + timeout_s
            return
        if k == 0:
            self.publish(self.device.sample())  # start-up: a late subscriber may have missed it
            self.deadline = now + STARTUP_RESEND_S
            return
        self.log.warning(
            f"no {EFFORT_COMMAND} for cycle {k} (stamp {k * self.period_ns * 1e-9:.3f} s) within "
            f"{timeout_s:g} s; is controller_node running and "
            "receiving its inputs? Sending the sample again."
        )
        self.publish(self.device.sample())
        self.deadline = now + timeout_s

    def tick(self, now: float) -> None:
        """Real time: apply the newest valid command (zero when the watchdog trips), send the
        next sample, schedule the next tick on the grid (sample 0 on the first)."""
        period = self.period_ns * 1e-9
        if not self.started:
            self.started = True
            self.t_first = now
            self.publish(self.device.sample())
            self.deadline = now + period
            return
        k = self.device.k
        grid = self.realtime.tick_at(self.grid, now - self.t_first, period)  # counts overruns
        self.realtime.tick(k)  # late when command k did not come (once the loop has closed)
        effort = self.latest
        if self.watchdog.due(self.ticks, self.settings.command_timeout_s):
            effort = self.zero
        self.advance(effort)
        self.grid = grid
        self.ticks += 1
        self.send_sample()
        self.news.say(now)
        self.deadline = self.t_first + (grid + 1) * period

    # --- end ------------------------------------------------------------------------------
    def stats(self) -> CycleStats:
        """Real-time cycle statistics so far."""
        g = self.guard
        return self.realtime.result(self.device.k, g.refused, g.limited, self.watchdog.trips)

    def shutdown(self) -> None:
        """Zero effort first; in real time one last period runs and is reported with it."""
        self.latest = self.zero
        if not self.lockstep and self.started:
            self.advance(self.zero)
            self.send_sample()
        self.news.say(float("inf"))  # the watchdog's last news, however soon after a line
