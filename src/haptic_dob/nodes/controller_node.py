"""controller_node: the OL / CL / DOB impedance law. Stamp-k inputs -> effort_command k.

Inputs: ``wrench_desired`` (the wall), ``joint_states`` (for J(q); not subscribed when the model's
Jacobian is constant, as on the slide), and, as the mode needs them, ``wrench_measured`` (CL) or
``wrench_estimate`` (DOB). Command k goes out as soon as every input of stamp k the mode needs
has arrived, labelled with its stamp and the session's command token (``effort@<ns>#<token>``).
``mode``, ``kf`` and ``max_force_n`` change at run time, bumpless (the next command uses the new
law); a switch to CL or DOB is refused while its force input is not flowing.

Fallback: when the mode's force input stops (its newest sample more than ``input_timeout_s`` of
sample time older than the cycle) it renders ``fallback`` (``zero`` or ``OL``), says so, and
returns to its mode once the input flows again; only sample stamps decide, never the wall clock
(docs/safety.md). Without ``wrench_desired`` it sends nothing and the device's watchdog zeroes
the effort. ``/diagnostics`` reports the mode, the fallback state and the inputs still awaited.
"""

from __future__ import annotations

import sys
import time
from collections.abc import Mapping
from typing import Any

from rclpy.context import Context

from haptic_dob.core.command_authority import new_token
from haptic_dob.core.command_join import CommandJoin
from haptic_dob.core.control import HandForce, ImpedanceController, ImpedanceLaw
from haptic_dob.core.joint_states import JointMap, pick
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.settings import (
    CommandOutputSettings,
    ControllerSettings,
    LoopInputs,
    LoopTiming,
    ProcessSettings,
)
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.stamps import period_ns
from haptic_msgs_py.topics import (
    EFFORT_COMMAND,
    JOINT_STATES,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)
from haptic_msgs_py.values import EffortCommand, JointSample, StampedVector


def controller_node_specs() -> list[ParamSpec]:
    """Every parameter of the controller node."""
    return [
        *specs_of(LoopTiming),
        *specs_of(LoopInputs),
        *specs_of(CommandOutputSettings),
        *specs_of(ProcessSettings),
        *model_specs(),
        *specs_of(ImpedanceLaw),
        *specs_of(ControllerSettings),
    ]


class ControllerNode(LoopNode):
    """Computes command k from the stamp-k inputs its mode needs (``core.command_join``)."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "controller_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=controller_node_specs(), context=context, namespace=namespace)
        values = self.params.values
        self.model = build_model(values)
        self.period_ns = period_ns(values["rate_hz"])
        log = self.log
        self.join = CommandJoin(
            ImpedanceController(self.model, build(ImpedanceLaw, values)),
            self.period_ns,
            needs_q=not self.model.constant_jacobian,
            input_timeout_ns=values["input_timeout_s"] * 1e9,
            fallback=values["fallback"],
            warn=log.warning,
            info=log.info,
        )
        self.joints = JointMap(self.model.joint_names)
        self._pending_since = 0.0
        self._warned_ns = -1
        self._last: EffortCommand | None = None
        self._token = values["command_token"] or new_token()
        self._pub = LoopPublisher(self, EFFORT_COMMAND, codecs.EFFORT, qos.LOOP)
        inputs: list[tuple[str, codecs.Codec, Any]] = [
            (WRENCH_DESIRED, codecs.WRENCH, self._on_desired)
        ]
        warm = values["warm_inputs"]
        start_need = self.join.law.needs
        if warm or start_need is HandForce.MEASURED:
            inputs.append((WRENCH_MEASURED, codecs.WRENCH, self._on_measured))
        if warm or start_need is HandForce.ESTIMATED:
            inputs.append((WRENCH_ESTIMATE, codecs.WRENCH, self._on_estimated))
        if self.join.needs_q:
            inputs.append((JOINT_STATES, codecs.JOINT_STATE, self._on_joint_states))
        profile = qos.loop_input(values["input_reliability"])
        for topic, codec, callback in inputs:  # first: heard before off-path work (timing.md)
            LoopSubscription(self, topic, codec, callback, profile, first=True)
        self.diagnostics = Diagnostics(self, self._report)
        self.params.set_validator(self._settings, self._apply)

    @property
    def controller(self) -> ImpedanceController:
        """The law and the model's Jacobian."""
        return self.join.controller

    # --- parameters ------------------------------------------------------------------------
    def next_sample_ns(self) -> int | None:
        """The command after the newest sent is the first computed with a new law."""
        sent = self.join.sent_ns
        return None if sent < 0 else sent + self.period_ns

    def _settings(self, values: Mapping[str, Any]) -> ImpedanceLaw:
        law = build(ImpedanceLaw, values)
        self.join.check_switch(law)
        return law

    def _apply(self, law: ImpedanceLaw) -> None:
        values = self.params.values
        self.join.input_timeout_ns = values["input_timeout_s"] * 1e9
        self.join.fallback = values["fallback"]
        self.join.set_law(law)
        self.log.info(
            f"law now {law.mode.value}, Kf {law.kf:g}, max {law.max_force_n:g} N, from the cycle "
            f"after stamp_ns {self.join.sent_ns}"
        )

    # --- inputs ----------------------------------------------------------------------------
    def _on_joint_states(self, js: JointSample) -> None:
        try:
            idx = self.joints.index(js.name, len(js.position))
            q = pick(js.position, idx, "position", len(js.name) or len(js.position))
        except ValueError as exc:
            self.log.error(f"ignoring joint_states: {exc}", throttle_duration_sec=5.0)
            return
        self._opened(js.stamp_ns)
        self._send(self.join.joints(js.stamp_ns, q))

    def _on_desired(self, wrench: StampedVector) -> None:
        self._opened(wrench.stamp_ns)
        self._send(self.join.wall(wrench.stamp_ns, wrench.vector))

    def _on_measured(self, wrench: StampedVector) -> None:
        self._send(self.join.measured(wrench.stamp_ns, wrench.vector))

    def _on_estimated(self, wrench: StampedVector) -> None:
        self._send(self.join.estimated(wrench.stamp_ns, wrench.vector))

    def _opened(self, stamp: int) -> None:
        """A cycle-defining input with a newer stamp opens a new pending cycle (for the warning
        that names what it still lacks)."""
        if stamp > self.join.newest_ns:
            self._pending_since = time.monotonic()

    def _send(self, command: list[float] | None) -> None:
        if command is None:
            return
        last = self._last
        if last is None or last.stamp_ns != self.join.sent_ns:
            last = self._last = EffortCommand(self.join.sent_ns, tuple(command), self._token)
            self.diagnostics.tick()
        self._pub.publish(last)  # a repeated sample gets the same command again

    # --- time ------------------------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        """While a cycle is pending: when to name the inputs it still lacks."""
        join = self.join
        if join.pending() and join.newest_ns != self._warned_ns:
            warn_s: float = self.params.values["input_warn_s"]
            return self._pending_since + warn_s
        return None

    def on_wakeup(self, now: float) -> None:
        """Name the inputs a pending cycle still lacks (once per cycle)."""
        self._warned_ns = self.join.newest_ns
        self.log.warning(
            f"cycle at stamp {self.join.newest_ns * 1e-9:.3f} s still lacks "
            f"{', '.join(self.join.missing_inputs())} after {now - self._pending_since:.1f} s"
        )

    def missing_inputs(self) -> list[str]:
        """The inputs of the newest pending cycle the current mode still waits for."""
        return self.join.missing_inputs()

    def _report(self) -> Report:
        join = self.join
        law = join.law
        fallback = self.params.values["fallback"]
        values = {
            "mode": law.mode.value,
            "kf": law.kf,
            "max_force_n": law.max_force_n,
            "fallback": f"active ({fallback}): {join.fallback_reason}"
            if join.fallback_reason
            else "inactive",
            "fallbacks": join.fallbacks,
            "awaiting": ", ".join(join.missing_inputs()) if join.pending() else "",
        }
        if join.fallback_reason:
            return WARN, f"fallback {fallback}: {join.fallback_reason}", values
        if self.diagnostics.cycles and self.diagnostics.rate_hz == 0.0:
            return WARN, "no commands in the last second: inputs missing", values
        return OK, f"running {join.mode_text()}", values


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob controller_node``."""
    return main_for(ControllerNode, args, controller_node_specs())


if __name__ == "__main__":
    sys.exit(main())
