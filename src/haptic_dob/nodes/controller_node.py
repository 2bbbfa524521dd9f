"""controller_node: the OL / CL / DOB impedance law. Stamp-k inputs -> effort_command k.

Inputs: ``wrench_desired`` (the wall), ``joint_states`` (for J(q); not subscribed when the model's
Jacobian is constant, as on the slide), and, as the mode needs them, ``wrench_measured`` (CL) or
``wrench_estimate`` (DOB). Command k goes out as soon as every input
of stamp k the mode needs has arrived, labelled with its stamp (``effort@<ns>``). ``mode``, ``kf``
and ``max_force_n`` change at run time: the next command uses the new law, with no other state to
carry (bumpless). A switch to CL or DOB is refused while its force input is not flowing (the
observer must be warm before DOB takes over).

Fallback: when the force input the mode needs stops (the observer died in DOB, the sensor stream in
CL) -- its newest sample is more than ``input_timeout_s`` of sample time older than the cycle --
the controller renders with ``fallback`` (``zero``: no force; ``OL``: the wall force alone), says
so, and returns to its mode once the input flows again (warm, as for a switch). Right after a
switch the new input may lag behind the cycle (off the lockstep critical path until then): while
it still flows the controller waits for it instead of falling back, so the switch stays bumpless.
Only sample stamps decide, never the wall clock, so a lockstep run stays deterministic under any
load (a dead input stalls it instead, and the device and controller say which input is missing);
in real time the device's watchdog zeroes the force while the controller waits.
Without the wall force (``wrench_desired``) it sends nothing and the device's watchdog zeroes the
effort. ``/diagnostics`` reports the mode, the fallback state and the inputs still awaited.
"""

from __future__ import annotations

import sys
import time
from collections import deque
from collections.abc import Mapping
from typing import Any

import numpy as np
from rclpy.context import Context

from haptic_dob.control import ZERO_FORCE, ControlMode, ImpedanceController, ImpedanceLaw
from haptic_dob.models.factory import build_model, model_specs
from haptic_dob.nodes.common import loop_specs, main_for, process_specs
from haptic_dob.nodes.observer_node import JointMap, pick
from haptic_msgs_py import wire
from haptic_msgs_py.convert import read_force
from haptic_msgs_py.params import ParamSpec, build, specs_of
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_msgs_py.ros.params import ParameterTable
from haptic_msgs_py.ros.raw import RawPublisher, raw_subscription
from haptic_msgs_py.ros.spin import LoopNode
from haptic_msgs_py.stamps import command_label, to_ns
from haptic_msgs_py.topics import (
    EFFORT_COMMAND,
    JOINT_STATES,
    SESSION_TOPICS,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)

#: a force input counts as flowing when this many of its samples came within the last
#: WARM_WINDOW cycles (a few may be late or lost: loop inputs are best effort)
WARM_SAMPLES = 20
WARM_WINDOW = 100
INPUT_TOPIC = {"measured": WRENCH_MEASURED, "estimated": WRENCH_ESTIMATE}


class _Input:
    """The newest message of one input (stamp in ns, value) and the stamps of the last few."""

    __slots__ = ("recent", "stamp", "value")

    def __init__(self) -> None:
        self.stamp = -1
        self.value: Any = ZERO_FORCE
        self.recent: deque[int] = deque(maxlen=WARM_SAMPLES)

    def take(self, stamp: int, value: Any) -> None:
        self.stamp = stamp
        self.value = value
        self.recent.append(stamp)

    def flowing(self, newest: int, period_ns: int) -> bool:
        """WARM_SAMPLES samples arrived within the WARM_WINDOW cycles up to ``newest``."""
        r = self.recent
        return len(r) == WARM_SAMPLES and r[0] >= newest - WARM_WINDOW * period_ns


def controller_node_specs() -> list[ParamSpec]:
    """Every parameter of the controller node."""
    return [
        *loop_specs(),
        *process_specs(),
        *model_specs(),
        *specs_of(ImpedanceLaw),
        ParamSpec(
            "input_warn_s",
            2.0,
            "warn when an input of a pending cycle is this late",
            "s",
            0.01,
            3600.0,
        ),
        ParamSpec(
            "warm_inputs",
            True,
            "subscribe to every mode's force input, so a switch to CL or DOB finds it flowing "
            "(false: only the start mode's input; cheaper; a switch to another mode is refused)",
            read_only=True,
        ),
        ParamSpec(
            "fallback",
            "zero",
            "what to render when the mode's force input stops: zero force or OL",
            choices=("zero", "OL"),
        ),
        ParamSpec(
            "input_timeout_s",
            0.02,
            "the mode's force input counts as stopped when its newest sample is this much sample "
            "time older than the cycle",
            "s",
            0.001,
            10.0,
        ),
    ]


class ControllerNode(LoopNode):
    """Computes command k from the stamp-k inputs its mode needs."""

    def __init__(self, context: Context | None = None, name: str = "controller_node") -> None:
        super().__init__(name, context=context)
        self.params = ParameterTable(self, controller_node_specs(), self._settings, self._apply)
        values = self.params.values
        self.model = build_model(values)
        self.period_ns = round(1e9 / values["rate_hz"])
        self.controller = ImpedanceController(self.model, self.params.settings)
        self.joints = JointMap(self.model.joint_names)
        self.js = _Input()
        self.desired = _Input()
        self.measured = _Input()
        self.estimated = _Input()
        self._q: list[float] = [0.0] * self.model.dof
        self._sent_ns = -1
        self._newest_ns = -1
        self._needs_q = not self.model.constant_jacobian
        self._pending_since = 0.0
        self._warned_ns = -1
        self.fallback_reason: str | None = None
        self.fallbacks = 0
        # after a switch to a mode with a force input: wait while that input, still flowing,
        # catches up with the cycle (off the lockstep critical path until now, it may lag)
        self._catching_up = False
        self._cmd = wire.float64_multi_array("", [0.0] * self.model.dof)
        self._dim = self._cmd.layout.dim[0]
        self._pub = RawPublisher(self, SESSION_TOPICS[EFFORT_COMMAND], EFFORT_COMMAND, qos.LOOP)
        inputs = [(WRENCH_DESIRED, self._on_desired)]
        warm = values["warm_inputs"]
        start_need = self.controller.law.needs
        if warm or start_need == "measured":
            inputs.append((WRENCH_MEASURED, self._on_measured))
        if warm or start_need == "estimated":
            inputs.append((WRENCH_ESTIMATE, self._on_estimated))
        if self._needs_q:
            inputs.append((JOINT_STATES, self._on_joint_states))
        for topic, callback in inputs:
            raw_subscription(self, SESSION_TOPICS[topic], topic, callback, qos.LOOP_IN)
        self.diagnostics = Diagnostics(self, self._report)

    # --- parameters ------------------------------------------------------------------------
    def _settings(self, values: Mapping[str, Any]) -> ImpedanceLaw:
        law = build(ImpedanceLaw, values)
        if hasattr(self, "controller"):  # a change at run time, not the start-up values
            need = law.needs
            old = self.controller.law.needs
            if need is not None and need != old:
                source = self.measured if need == "measured" else self.estimated
                if not source.flowing(self._newest_ns, self.period_ns):
                    raise ValueError(
                        f"mode {law.mode.value} needs {INPUT_TOPIC[need]}, which is not flowing "
                        f"(fewer than {WARM_SAMPLES} samples in the last {WARM_WINDOW} cycles)"
                    )
        return law

    def _apply(self, law: ImpedanceLaw) -> None:
        if law.needs is not None and law.needs != self.controller.law.needs:
            self._catching_up = True  # the new input may lag (it was off the critical path)
        self.controller.law = law
        self.get_logger().info(
            f"law now {law.mode.value}, Kf {law.kf:g}, max {law.max_force_n:g} N, from the cycle "
            f"after stamp_ns {self._sent_ns}"
        )

    # --- inputs ----------------------------------------------------------------------------
    def _on_joint_states(self, msg: Any) -> None:
        st = msg.header.stamp
        try:
            idx = self.joints.index(msg.name, len(msg.position))
            self._q = pick(msg.position, idx, "position", len(msg.name) or len(msg.position))
        except ValueError as exc:
            self.get_logger().error(f"ignoring joint_states: {exc}", throttle_duration_sec=5.0)
            return
        stamp = to_ns(st.sec, st.nanosec)
        self._note(stamp)
        self.js.take(stamp, self._q)
        self._emit()

    def _on_desired(self, msg: Any) -> None:
        st = msg.header.stamp
        stamp = to_ns(st.sec, st.nanosec)
        self._note(stamp)
        self.desired.take(stamp, read_force(msg))
        self._emit()

    def _note(self, stamp: int) -> None:
        """A cycle-defining input with a newer stamp opens a new pending cycle."""
        if stamp > self._newest_ns:
            self._newest_ns = stamp
            self._pending_since = time.monotonic()

    def _on_measured(self, msg: Any) -> None:
        st = msg.header.stamp
        self.measured.take(to_ns(st.sec, st.nanosec), read_force(msg))
        if self.controller.law.mode is ControlMode.CL:
            self._emit()

    def _on_estimated(self, msg: Any) -> None:
        st = msg.header.stamp
        self.estimated.take(to_ns(st.sec, st.nanosec), read_force(msg))
        if self.controller.law.mode is ControlMode.DOB:
            self._emit()

    def _force_input(self) -> tuple[_Input, str] | None:
        """The hand-force input the current mode needs, with its topic (None in OL)."""
        need = self.controller.law.needs
        if need is None:
            return None
        return (
            (self.measured, WRENCH_MEASURED)
            if need == "measured"
            else (self.estimated, WRENCH_ESTIMATE)
        )

    # --- the law ---------------------------------------------------------------------------
    def _emit(self) -> None:
        k = self._newest_ns
        if k < self._sent_ns or self.desired.stamp != k:
            return
        if self._needs_q and self.js.stamp != k:
            return
        force = self._force_input()
        if force is not None:
            src, topic = force
            if src.stamp == k:
                self._catching_up = False
                if self.fallback_reason and src.flowing(k, self.period_ns):
                    self.fallback_reason = None
                    self.get_logger().info(f"{topic} flows again: back to {self._mode()}")
            elif not self.fallback_reason:
                timeout_ns = self.params.values["input_timeout_s"] * 1e9
                if k - src.stamp <= timeout_ns:
                    return  # on its way: wait for it
                if self._catching_up and src.flowing(k, self.period_ns):
                    return  # lagging behind after a switch, but coming: wait for it
                self._fall_back(f"{topic} silent for {(k - src.stamp) * 1e-6:.0f} ms of samples")
        if k != self._sent_ns:
            if self.fallback_reason is None:
                tau = self.controller.command(
                    self.js.value, self.desired.value, self.measured.value, self.estimated.value
                )
            elif self.params.values["fallback"] == "OL":
                tau = self._open_loop.command(self.js.value, self.desired.value)
            else:
                tau = [0.0] * self.model.dof
            self._cmd.data = np.array(tau)
            self._dim.label = command_label(k)
            self._sent_ns = k
            self.diagnostics.tick()
        self._pub.publish(self._cmd)  # a repeated sample gets the same command again

    def _mode(self) -> str:
        law = self.controller.law
        return law.mode.value if law.mode is ControlMode.OL else f"{law.mode.value} (Kf {law.kf:g})"

    @property
    def _open_loop(self) -> ImpedanceController:
        """OL with the current force limit (the OL fallback)."""
        limit = self.controller.law.max_force_n
        ol = getattr(self, "_ol", None)
        if ol is None or ol.law.max_force_n != limit:
            self._ol = ImpedanceController(self.model, ImpedanceLaw(ControlMode.OL, 0.0, limit))
        return self._ol

    def _fall_back(self, reason: str) -> None:
        self.fallback_reason = reason
        self.fallbacks += 1
        self.get_logger().warning(
            f"{self._mode()} lost its input ({reason}): rendering "
            f"{self.params.values['fallback']} until it flows again"
        )

    def next_wakeup(self) -> float | None:
        """While a cycle is pending: when to name the inputs it still lacks."""
        if self._newest_ns > self._sent_ns and self._newest_ns != self._warned_ns:
            return self._pending_since + self.params.values["input_warn_s"]
        return None

    def on_wakeup(self, now: float) -> None:
        """Name the inputs a pending cycle still lacks (once per cycle)."""
        self._warned_ns = self._newest_ns
        self.get_logger().warning(
            f"cycle at stamp {self._newest_ns * 1e-9:.3f} s still lacks "
            f"{', '.join(self.missing_inputs())} after {now - self._pending_since:.1f} s"
        )

    def _report(self) -> Report:
        law = self.controller.law
        values = {
            "mode": law.mode.value,
            "kf": law.kf,
            "max_force_n": law.max_force_n,
            "fallback": f"active ({self.params.values['fallback']}): {self.fallback_reason}"
            if self.fallback_reason
            else "inactive",
            "fallbacks": self.fallbacks,
            "awaiting": ", ".join(self.missing_inputs()) if self._newest_ns > self._sent_ns else "",
        }
        if self.fallback_reason:
            return (
                WARN,
                f"fallback {self.params.values['fallback']}: {self.fallback_reason}",
                values,
            )
        if self.diagnostics.cycles and self.diagnostics.rate_hz == 0.0:
            return WARN, "no commands in the last second: inputs missing", values
        return OK, f"running {self._mode()}", values

    def missing_inputs(self) -> list[str]:
        """The inputs of the newest pending cycle the current mode still waits for."""
        k = self._newest_ns
        out = [] if self.desired.stamp == k else [WRENCH_DESIRED]
        if self._needs_q and self.js.stamp != k:
            out.append(JOINT_STATES)
        need = self.controller.law.needs
        if need == "measured" and self.measured.stamp != k:
            out.append(WRENCH_MEASURED)
        if need == "estimated" and self.estimated.stamp != k:
            out.append(WRENCH_ESTIMATE)
        return out


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob controller_node``."""
    return main_for(ControllerNode, args)


if __name__ == "__main__":
    sys.exit(main())
