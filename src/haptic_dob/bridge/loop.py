"""The bridge's cycle, ROS-free: a driver state to the loop, the loop's command to the driver.

``on_state`` turns driver state k into the loop's sample k (q, q', the effort in force over
[k-1, k) by the driver's clock, ``DriverClock``; the tip's point and velocity; the driver's
stamp); ``on_command`` turns the loop's command for it into the driver's at once (``CommandMap``,
``CommandLimiter``); ``book`` counts it after the send (``AnswerTiming``). Every way out is zero:

- before ``start``, after ``stop``, and while the dead-man is released or never seen: zero on
  every state;
- no valid command for ``safety.command_timeout_s`` (in driver states): zero until one comes;
- no state for ``state.timeout_s`` (wall clock, ``on_wakeup``): zero, again every timeout, and
  no command for the last state is taken;
- a command of the wrong length or with NaN/inf is refused (zero); one for a sample older than
  the newest answered, or not handed on, is dropped; nothing non-finite is sent. docs/safety.md.
"""

from __future__ import annotations

import math
from collections import deque
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
from numpy.typing import NDArray

from haptic_dob.bridge.answers import AnswerTiming
from haptic_dob.bridge.command import CommandLimiter, CommandMap
from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.settings import SafetySettings
from haptic_dob.bridge.state import DriverState
from haptic_dob.bridge.timeline import DriverClock, SentLog
from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.watchdog import CommandWatchdog
from haptic_msgs_py.stamps import period_ns
from haptic_msgs_py.values import EffortCommand

Vec3 = tuple[float, float, float]


class LoopSample(NamedTuple):
    """Driver state k in the suite's contract (SI, model joint order, the driver's stamp)."""

    stamp_ns: int
    q: tuple[float, ...]
    qd: tuple[float, ...]
    effort: tuple[float, ...]  # in force over [k-1, k)
    ee_position: Vec3
    ee_velocity: Vec3


class Send(NamedTuple):
    """A command for the driver: its elements in the driver's units, the sample it answers
    (ns; the newest state's for a zero), and why it is zero ('' for the loop's command)."""

    values: tuple[float, ...]
    stamp_ns: int
    zero_because: str


def _quiet(_text: str) -> None:
    """Say nothing."""


class BridgeLoop:
    """One driver's bridge to the loop (see the module's notes).

    Args:
        driver: the driver's settings (``DriverSettings.of``).
        safety: the clamp, rate limit, command timeout and dead-man.
        model: the device model the loop uses (its kinematics give the tip's point).
        driver_joints: the driver's name of each model joint (``StateReader.driver_joints``).
        rate_hz: the driver's rate (Hz).
        say: where the loop says a trip or a resumption (once each).
    """

    def __init__(
        self,
        driver: DriverSettings,
        safety: SafetySettings,
        model: DeviceModel,
        driver_joints: tuple[str, ...],
        rate_hz: float,
        say: Callable[[str], None] = _quiet,
    ) -> None:
        self.model = model
        self.map = CommandMap(driver, model, driver_joints)
        n = self.map.size
        self.period_s = period_ns(rate_hz) * 1e-9
        self.limiter = CommandLimiter(safety.limits_for(n), safety.rates_for(n), self.period_s)
        self.scale = driver.command.scale
        self.command_timeout_s = safety.command_timeout_s
        self.state_timeout_s = driver.state.timeout_s
        self.effort_source = driver.effort
        self.watchdog = CommandWatchdog(period_ns(rate_hz), self._tripped, self._resumed)
        self._say = say
        self._zero_model = (0.0,) * model.dof
        self.clock = DriverClock(self.period_s)
        self._sent = SentLog((0.0,) * n)  # the driver's elements sent, by send time
        #: the previous state's q and tip Jacobian (None: not known)
        self._prev: tuple[tuple[float, ...], NDArray[np.float64] | None] = (self._zero_model, None)
        #: the instants of the newest states: the effort over [k-1, k) is the newest sent
        #: before the instant of state k - delay_samples (the driver's update that wrote it)
        self._instants: deque[float] = deque(maxlen=driver.delay_samples + 1)
        self._newest_instant = 0.0
        self.deadman_held = safety.deadman == "none"
        self.started = False
        self.stopping = False
        self.state_stale = False
        self.state_deadline: float | None = None  # monotonic s: no state by then trips
        self.k = 0  # states handed on
        self.newest_ns = -1  # stamp of the newest state handed on
        self.answered_ns = -1  # stamp of the newest sample commanded
        self._newest_q: tuple[float, ...] = self._zero_model
        self.timing = AnswerTiming()  # on time, late, latency (``book``: after the send)
        self.states = 0
        self.refused = self.dropped = self.gated = self.zeros = 0
        self.state_trips = self.deadman_releases = self.repeated = 0

    # --- the driver's state --------------------------------------------------------------
    def on_state(
        self, s: DriverState, now: float, now_ns: int | None = None
    ) -> tuple[LoopSample | None, Send | None]:
        """Driver state ``s`` arrived at monotonic ``now`` (s), on the system clock at
        ``now_ns`` (None: not known): the loop's sample (None while not handing on) and a zero
        to send first (None when none is due)."""
        self.book()
        if self.stopping:
            return None, None
        if s.stamp_ns <= self.newest_ns:  # a stamp that did not advance: not a new state
            self.repeated += 1
            if self.repeated == 1:
                self._say(
                    "the driver's state stamps do not advance (a state stamped "
                    f"{s.stamp_ns} after {self.newest_ns}): such states are not handed on; "
                    "state.stamp: receipt stamps them on arrival"
                )
            return None, None
        self.states += 1
        self.state_deadline = now + self.state_timeout_s
        if self.state_stale:
            self.state_stale = False
            self._say("driver state again: the loop resumes")
        instant = self.clock.heard(s.stamp_ns, now, now_ns)
        self._instants.append(instant)
        if not self.started:
            return None, self._zero(s.stamp_ns, "the loop is not up yet", now)
        self.timing.arrived(s.stamp_ns, now, self.answered_ns != self.newest_ns)
        self.k += 1
        self.newest_ns, self._newest_q = s.stamp_ns, s.q
        self._newest_instant = instant
        zero = None
        if self.watchdog.due(self.k, self.command_timeout_s):
            zero = self._zero(s.stamp_ns, "no loop command", now)
        elif not self.deadman_held:
            zero = self._zero(s.stamp_ns, "dead-man released", now)
        return self._sample(s), zero

    def _sample(self, s: DriverState) -> LoopSample:
        if self.effort_source == "driver":
            if s.effort is None:
                raise ValueError(
                    "the driver's state has no effort (state.effort must be commanded)"
                )
            effort = s.effort
        else:
            full = len(self._instants) == self._instants.maxlen
            u = self._sent.newest_before(self._instants[0]) if full else None
            # as a driver applies it over [k-1, k): at the posture of state k-1
            effort = self._zero_model if u is None else self.map.back(u, *self._prev)
        q = np.asarray(s.q, dtype=np.float64)
        p = self.model._forward_kinematics(q)
        J = self.model._jacobian(q)
        self._prev = (s.q, J)
        v = J @ np.asarray(s.qd, dtype=np.float64)
        return LoopSample(s.stamp_ns, s.q, s.qd, effort, (p[0], p[1], p[2]), (v[0], v[1], v[2]))

    # --- the loop's command ----------------------------------------------------------------
    def on_command(self, cmd: EffortCommand, now: float) -> Send | None:
        """The loop's command arrived at monotonic ``now`` (s): the driver's command, a zero
        (refused), or None (dropped: stale, blocked, or after the stop). ``book`` counts it."""
        self.book()
        if self.stopping:
            return None
        stamp = self.newest_ns if cmd.stamp_ns is None else cmd.stamp_ns
        if not self.started or self.state_stale or not self.answered_ns < stamp <= self.newest_ns:
            self.dropped += 1
            return None
        tau = cmd.effort
        if len(tau) != self.model.dof or not all(map(math.isfinite, tau)):
            self.refused += 1
            return self._zero(stamp, "refused a command of the wrong length or with NaN/inf", now)
        self.watchdog.fed(self.k)
        self.answered_ns = stamp
        newest = stamp == self.newest_ns
        self.timing.taken(stamp, now, newest, self._newest_instant + self.period_s)
        if not self.deadman_held:
            self.gated += 1
            return None
        q, J = self._prev  # the Jacobian made for the newest state's sample, if it was
        J = J if q is self._newest_q else None
        u = self.limiter.limit(self.map.forward(tau, self._newest_q, J))
        if not all(map(math.isfinite, u)):  # a singular map, say: never sent
            self.refused += 1
            return self._zero(stamp, "the command mapped to NaN/inf", now)
        self._sent.add(now, u)
        return Send(tuple(x * self.scale for x in u), stamp, "")

    def book(self) -> None:
        """Count and time the command taken last (``AnswerTiming.book``): after its send."""
        self.timing.book()

    # --- safety inputs and time -------------------------------------------------------------
    def on_deadman(self, held: bool, now: float) -> Send | None:
        """The dead-man is ``held`` at monotonic ``now`` (s): released sends zero at once."""
        was, self.deadman_held = self.deadman_held, held
        if was and not held:
            self.deadman_releases += 1
            self._say("dead-man released: zero command until it is held again")
            return self._zero(self.newest_ns, "dead-man released", now)
        if held and not was:
            self._say("dead-man held: the loop's commands pass")
        return None

    def on_wakeup(self, now: float) -> Send | None:
        """The state watchdog at monotonic ``now`` (s): zero when the driver's state stopped."""
        if self.stopping or self.state_deadline is None or now < self.state_deadline:
            return None
        self.state_deadline = now + self.state_timeout_s
        if not self.state_stale and self.started:
            self.state_stale = True
            self.state_trips += 1
            self.answered_ns = self.newest_ns  # no command for the stale state is taken
            self._say(
                f"no driver state for {self.state_timeout_s * 1e3:g} ms: zero command, the "
                f"stale state is not rendered ({self.state_trips} trips so far)"
            )
        return self._zero(self.newest_ns, "no driver state", now)

    def start(self) -> None:
        """Hand the driver's states to the loop from the next one on."""
        self.started = True

    def stop(self, now: float) -> Send:
        """The end at monotonic ``now`` (s): zero now, nothing after."""
        self.stopping = True
        return self._zero(self.newest_ns, "stopping", now)

    # --- what goes out as zero ----------------------------------------------------------------
    def _zero(self, stamp_ns: int, why: str, now: float) -> Send:
        self.zeros += 1
        u = self.limiter.zero()
        self._sent.add(now, u)
        return Send(u, max(stamp_ns, 0), why)

    def _tripped(self, held: str) -> None:
        self._say(
            f"watchdog: no valid loop command for {held} (limit "
            f"{self.command_timeout_s * 1e3:g} ms): zero command ({self.watchdog.trips} trips)"
        )

    def _resumed(self) -> None:
        self._say("loop command again: the driver's command resumes")

    def status(self) -> str:
        """Why the driver gets zero now ('' when the loop's commands pass)."""
        if not self.started:
            return "waiting for the loop"
        if self.state_stale:
            return "no driver state"
        if self.watchdog.tripped:
            return "no loop command"
        return "" if self.deadman_held else "dead-man released"

    def counts(self) -> dict[str, float]:
        """What the bridge counted so far (the stats file and the diagnostics)."""
        self.book()
        t = self.timing
        total = t.on_time + t.late
        return {
            "states": self.states,
            "handed_on": self.k,
            "commands_on_time": t.on_time,
            "commands_late": t.late,
            "on_time_pct": 100.0 * t.on_time / total if total else math.nan,
            "latency_p50_ms": t.latency.percentile(50) * 1e3,
            "latency_p99_ms": t.latency.percentile(99) * 1e3,
            "refused_commands": self.refused,
            "dropped_commands": self.dropped,
            "gated_commands": self.gated,
            "clamped_commands": self.limiter.clamped,
            "rate_limited_commands": self.limiter.slowed,
            "zeros_sent": self.zeros,
            "watchdog_trips": self.watchdog.trips,
            "state_trips": self.state_trips,
            "deadman_releases": self.deadman_releases,
            "states_not_advancing": self.repeated,
            "state_age_ms": self.clock.age_s * 1e3,
        }
