"""The controller's decision, ROS-free: command k from the stamp-k inputs its mode needs.

``CommandJoin`` joins inputs by their sample stamps (never by the wall clock, so a lockstep run
stays deterministic under any load), refuses a switch to a mode whose force input is not flowing
(the warm-up), renders ``fallback`` when that input stops, and right after a switch waits for
the new input while it catches up (bumpless). The controller node runs it on its topics,
``haptic_dob.core.cycle.LoopCycle`` in-process.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable, Sequence
from typing import Any

from haptic_dob.core.control import (
    ZERO_FORCE,
    ControlMode,
    Force,
    HandForce,
    ImpedanceController,
    ImpedanceLaw,
)

#: a force input counts as flowing when this many of its samples came within the last
#: WARM_WINDOW cycles (a few may be late or lost: loop inputs may be best effort)
WARM_SAMPLES = 20
WARM_WINDOW = 100
FALLBACKS = ("zero", "OL")


class ForceInput:
    """The newest sample of one input (stamp in ns, value) and the stamps of the last few."""

    __slots__ = ("recent", "stamp", "value")

    def __init__(self, value: Any = ZERO_FORCE) -> None:
        self.stamp = -1
        self.value: Any = value
        self.recent: deque[int] = deque(maxlen=WARM_SAMPLES)

    def take(self, stamp: int, value: Any) -> None:
        """Hold ``value`` as the input of stamp ``stamp`` (ns)."""
        self.stamp = stamp
        self.value = value
        self.recent.append(stamp)

    def flowing(self, newest: int, period_ns: int) -> bool:
        """WARM_SAMPLES samples arrived within the WARM_WINDOW cycles up to ``newest``."""
        r = self.recent
        return len(r) == WARM_SAMPLES and r[0] >= newest - WARM_WINDOW * period_ns


def _quiet(_text: str) -> None:
    return None


class CommandJoin:
    """Command k from the stamp-k inputs its mode needs (the controller's decision, ROS-free).

    Feed the inputs as they come (``wall``, ``joints``, ``measured``, ``estimated``; stamps in ns):
    each returns the command to send (joint efforts, N or N m) once every input of the newest cycle
    is there, the same again for a repeated sample, None while one is missing or for a stale sample.

    Args:
        controller: the law and the model's Jacobian (its ``law`` is replaced by ``set_law``).
        period_ns: the sample period (ns).
        needs_q: whether J depends on q (then ``joint_states`` of stamp k is an input too).
        input_timeout_ns: the mode's force input counts as stopped when its newest sample is this
            much sample time older than the cycle.
        fallback: what to render while it is stopped: ``zero`` or ``OL`` (the wall force alone).
        warn, info: where the join reports a fallback and a recovery (default: nowhere).
    """

    def __init__(
        self,
        controller: ImpedanceController,
        period_ns: int,
        needs_q: bool,
        input_timeout_ns: float = 20_000_000,
        fallback: str = "zero",
        warn: Callable[[str], object] = _quiet,
        info: Callable[[str], object] = _quiet,
    ) -> None:
        if fallback not in FALLBACKS:
            raise ValueError(f"fallback must be one of {', '.join(FALLBACKS)}, got {fallback!r}")
        self.controller = controller
        self.period_ns = period_ns
        self.needs_q = needs_q
        self.input_timeout_ns = input_timeout_ns
        self.fallback = fallback
        self._warn, self._info = warn, info
        dof = controller.model.dof
        self.joints_in = ForceInput([0.0] * dof)
        self.desired = ForceInput()
        self.measured_in = ForceInput()
        self.estimated_in = ForceInput()
        self.sent_ns = -1  # stamp of the newest command computed
        self.newest_ns = -1  # stamp of the newest cycle an input opened
        self.awaited_ns = -1  # the first cycle that waited for a force input never received
        self.fallback_reason: str | None = None
        self.fallbacks = 0
        # after a switch to a mode with a force input: wait while that input, still flowing,
        # catches up with the cycle (off the lockstep critical path until now, it may lag)
        self.catching_up = False
        self._command: list[float] = [0.0] * dof
        self._ol: ImpedanceController | None = None

    # --- the law ----------------------------------------------------------------------------
    @property
    def law(self) -> ImpedanceLaw:
        """The law in force."""
        return self.controller.law

    def check_switch(self, law: ImpedanceLaw) -> None:
        """``ValueError`` with the reason when ``law`` needs a force input that is not flowing."""
        need, old = law.needs, self.controller.law.needs
        if need is not None and need != old:
            source = self.measured_in if need is HandForce.MEASURED else self.estimated_in
            if not source.flowing(self.newest_ns, self.period_ns):
                raise ValueError(
                    f"mode {law.mode.value} needs {need.value}, which is not flowing "
                    f"(fewer than {WARM_SAMPLES} samples in the last {WARM_WINDOW} cycles)"
                )

    def set_law(self, law: ImpedanceLaw) -> None:
        """Use ``law`` from the next command on (check it with ``check_switch`` first)."""
        if law.needs is not None and law.needs != self.controller.law.needs:
            self.catching_up = True  # the new input may lag (it was off the critical path)
        self.controller.law = law

    def mode_text(self) -> str:
        """The mode in force, with Kf when it feeds a force back."""
        law = self.controller.law
        return law.mode.value if law.mode is ControlMode.OL else f"{law.mode.value} (Kf {law.kf:g})"

    # --- inputs -----------------------------------------------------------------------------
    def wall(self, stamp: int, force: Force) -> list[float] | None:
        """The wall force of sample ``stamp`` (a cycle-defining input)."""
        if stamp > self.newest_ns:
            self.newest_ns = stamp
        self.desired.take(stamp, force)
        return self._decide()

    def joints(self, stamp: int, q: Sequence[float]) -> list[float] | None:
        """The joint positions of sample ``stamp`` (a cycle-defining input when J depends on q)."""
        if stamp > self.newest_ns:
            self.newest_ns = stamp
        self.joints_in.take(stamp, q)
        return self._decide()

    def measured(self, stamp: int, force: Force) -> list[float] | None:
        """The force sensor's hand force of sample ``stamp``."""
        self.measured_in.take(stamp, force)
        return self._decide() if self.controller.law.mode is ControlMode.CL else None

    def estimated(self, stamp: int, force: Force) -> list[float] | None:
        """The observer's hand force of sample ``stamp``."""
        self.estimated_in.take(stamp, force)
        return self._decide() if self.controller.law.mode is ControlMode.DOB else None

    def force_input(self) -> tuple[ForceInput, str] | None:
        """The hand-force input the current mode needs, with its topic (None in OL)."""
        need = self.controller.law.needs
        if need is None:
            return None
        return (self.measured_in if need is HandForce.MEASURED else self.estimated_in), need.value

    def pending(self) -> bool:
        """A cycle is open whose command has not been computed."""
        return self.newest_ns > self.sent_ns

    def missing_inputs(self) -> list[str]:
        """The inputs of the newest cycle the current mode still waits for (topic names)."""
        k = self.newest_ns
        out = [] if self.desired.stamp == k else ["wrench_desired"]
        if self.needs_q and self.joints_in.stamp != k:
            out.append("joint_states")
        force = self.force_input()
        if force is not None and force[0].stamp != k:
            out.append(force[1])
        return out

    # --- the decision -----------------------------------------------------------------------
    def _decide(self) -> list[float] | None:
        k = self.newest_ns
        if k < self.sent_ns or self.desired.stamp != k:
            return None
        if self.needs_q and self.joints_in.stamp != k:
            return None
        force = self.force_input()
        if force is not None:
            src, topic = force
            if src.stamp == k:
                self.catching_up = False
                if self.fallback_reason and src.flowing(k, self.period_ns):
                    self.fallback_reason = None
                    self._info(f"{topic} flows again: back to {self.mode_text()}")
            elif not self.fallback_reason:
                if src.stamp < 0 and self.awaited_ns < 0:
                    self.awaited_ns = k  # none yet: silent from the first cycle that waits
                since = src.stamp if src.stamp >= 0 else self.awaited_ns
                if k - since <= self.input_timeout_ns:
                    return None  # on its way: wait for it
                if self.catching_up and src.flowing(k, self.period_ns):
                    return None  # lagging behind after a switch, but coming: wait for it
                silent = "silent for" if src.stamp >= 0 else "not received in the first"
                self._fall_back(f"{topic} {silent} {(k - since) * 1e-6:.0f} ms of samples")
        if k != self.sent_ns:
            if self.fallback_reason is None:
                self._command = self.controller.command(
                    self.joints_in.value,
                    self.desired.value,
                    self.measured_in.value,
                    self.estimated_in.value,
                )
            elif self.fallback == "OL":
                self._command = self._open_loop().command(self.joints_in.value, self.desired.value)
            else:
                self._command = [0.0] * self.controller.model.dof
            self.sent_ns = k
        return self._command  # a repeated sample gets the same command again

    def _open_loop(self) -> ImpedanceController:
        """OL with the current force limit (the OL fallback)."""
        limit = self.controller.law.max_force_n
        ol = self._ol
        if ol is None or ol.law.max_force_n != limit:
            ol = self._ol = ImpedanceController(
                self.controller.model, ImpedanceLaw(ControlMode.OL, 0.0, limit)
            )
        return ol

    def _fall_back(self, reason: str) -> None:
        self.fallback_reason = reason
        self.fallbacks += 1
        self._warn(
            f"{self.mode_text()} lost its input ({reason}): rendering {self.fallback} until it "
            "flows again"
        )
