"""observer_node: joint_states of sample k -> wrench_estimate k and effort_estimate k.

Runs the core ``DisturbanceObserver`` on the device model. Joints are matched by name (any order,
extra joints ignored); a sample without velocities is differentiated from positions. A sample
whose stamp was already handled is answered again with the same estimate (idempotent, so a
re-published sample in lockstep is safe); an older one is ignored. ``~/reset`` re-zeroes.
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any

from rclpy.context import Context
from std_srvs.srv import Trigger

from haptic_dob.core.control import ZERO_FORCE, Force
from haptic_dob.core.cycle import estimate
from haptic_dob.core.joint_states import JointMap, joint_vectors
from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.settings import LoopTiming, ProcessSettings
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import ERROR, OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.stamps import period_ns
from haptic_msgs_py.topics import EFFORT_ESTIMATE, JOINT_STATES, WRENCH_ESTIMATE
from haptic_msgs_py.values import JointSample, StampedVector


def observer_node_specs() -> list[ParamSpec]:
    """Every parameter of the observer node."""
    return [
        *specs_of(LoopTiming),
        *specs_of(ProcessSettings),
        *model_specs(),
        *specs_of(ObserverSettings),
    ]


class ObserverNode(LoopNode):
    """Publishes the estimated contact wrench and external joint effort of any device model."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "observer_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=observer_node_specs(), context=context, namespace=namespace)
        values = self.params.values
        self.model: DeviceModel = build_model(values)
        self.period_ns = period_ns(values["rate_hz"])
        settings = self._settings(values)
        self.observer: DisturbanceObserver = settings.build(self.model, self.period_ns * 1e-9)
        self.joints = JointMap(self.model.joint_names)
        self._last_ns = -1
        self.gaps = 0  # samples that came two periods or more after the previous one
        self._prev_q: list[float] | None = None
        self._bad_input_logged = ""
        self._force: Force = ZERO_FORCE
        self._names = tuple(self.model.joint_names)
        self._pub_wrench = LoopPublisher(
            self, WRENCH_ESTIMATE, codecs.WRENCH, qos.LOOP, values["base_frame"]
        )
        self._pub_effort = LoopPublisher(  # for evaluation: sent only while someone reads it
            self,
            EFFORT_ESTIMATE,
            codecs.JOINT_STATE,
            qos.LOOP,
            values["base_frame"],
            on_demand=True,
        )
        LoopSubscription(
            self, JOINT_STATES, codecs.JOINT_STATE, self._on_joint_states, qos.ESTIMATOR_IN
        )
        self.create_service(Trigger, "~/reset", self._on_reset)
        self.diagnostics = Diagnostics(self, self._report)
        self.params.set_validator(self._settings, self._apply)

    def _report(self) -> Report:
        values = {
            "model": self.params.values["model"],
            "gain": self.observer.gain,
            "output_limit": self.params.values["output_limit"],
            "initialised": self.observer.initialised,
            "sample_gaps": self.gaps,
            "bad_input": self._bad_input_logged or "none",
        }
        if self._bad_input_logged and self.diagnostics.rate_hz == 0.0:
            return ERROR, f"ignoring joint_states: {self._bad_input_logged}", values
        if self.diagnostics.rate_hz == 0.0:
            return WARN, "no joint_states in the last second", values
        return OK, "estimating", values

    def next_sample_ns(self) -> int | None:
        """The sample after the newest estimated is the first with a new gain."""
        last = self._last_ns
        return None if last < 0 else last + self.period_ns

    def drain_marker(self) -> int:
        """The newest sample handled: at a stop, the samples still queued are answered first."""
        return self._last_ns

    @staticmethod
    def _settings(values: Mapping[str, Any]) -> ObserverSettings:
        return build(ObserverSettings, values)

    def _apply(self, settings: ObserverSettings) -> None:
        """A new gain or limit, taken on the next sample without a jump of the estimate."""
        self.observer.retune(settings.gain, settings.output_limit or None)
        self.log.info(f"observer now {settings}")

    def _on_reset(self, _req: Trigger.Request, res: Trigger.Response) -> Trigger.Response:
        self.observer.reset()
        self._prev_q = None
        res.success = True
        res.message = "observer re-zeroed; it re-initialises on the next sample"
        return res

    def _on_joint_states(self, js: JointSample) -> None:
        now = js.stamp_ns
        if now < self._last_ns:
            return
        if now == self._last_ns:  # the same sample again: answer it again
            self._publish(now)
            return
        try:
            dt = (now - self._last_ns) * 1e-9 if self._prev_q is not None else 0.0
            q, qd, tau = joint_vectors(
                self.joints, js.name, js.position, js.velocity, js.effort, self._prev_q, dt
            )
        except ValueError as exc:
            self._complain(str(exc))
            return
        # periods since the previous sample: a real-time device's stamps (the system clock when
        # each sample was taken) are a period apart give or take its wake-up jitter
        jump = round((now - self._last_ns) / self.period_ns) if self._last_ns >= 0 else 1
        self._prev_q = q
        self._last_ns = now
        self._bad_input_logged = ""
        self._force = estimate(self.observer, q, qd, tau)
        self._publish(now)  # the estimate first, then what is said of it
        self.observer.prepare()  # the next update's dynamics, off the next command's path
        self.diagnostics.tick()
        if jump > 1:
            self.gaps += 1
            self.log.warning(
                f"joint_states jumped {jump:g} periods ({self.gaps} gaps so far); the update "
                "assumes one",
                throttle_duration_sec=5.0,
            )

    def _publish(self, stamp_ns: int) -> None:
        """The estimate of sample ``stamp_ns``: the wrench first (the controller may wait for
        it), the joint effort only when someone takes it."""
        self._pub_wrench.publish(StampedVector(stamp_ns, self._force))
        if self._pub_effort.wanted:
            effort = tuple(self.observer.estimate.tolist())
            self._pub_effort.publish(JointSample(stamp_ns, self._names, (), (), effort))

    def _complain(self, reason: str) -> None:
        if reason != self._bad_input_logged:  # once per distinct problem, not at 1 kHz
            self.log.error(f"ignoring joint_states: {reason}")
            self._bad_input_logged = reason


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob observer_node``."""
    return main_for(ObserverNode, args, observer_node_specs())


if __name__ == "__main__":
    sys.exit(main())
