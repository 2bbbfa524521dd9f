"""slave_controller_node: a teleoperation slave's joint impedance. joint_states k + pose_desired
k -> effort_command k.

Runs ``haptic_dob.teleop.slave.SlaveController``: a differential-IK step moves the joint target
toward ``pose_desired`` (the point the channel's slave end wants the tool at), and the joint
impedance around it plus the model's gravity gives the efforts, saturated at the model's limits.
Command k goes out once both inputs of stamp k are here, labelled with the stamp and the
session's command token (``command_token``, as the controller node's); a sample
answered already is answered again with the same command (a lockstep re-send). The gains are
set at the first sample's pose (``slave.*``, read-only). With ``slave.trajectory_path`` it plays
that excitation instead (``SlaveController.play``, time from the first sample's stamp): command k
goes out on joint_states k alone, and ``pose_desired`` is not read.
"""

from __future__ import annotations

import sys

import numpy as np
from rclpy.context import Context

from haptic_dob.core.command_authority import new_token
from haptic_dob.core.joint_states import JointMap, pick
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.settings import (
    CommandOutputSettings,
    LoopInputs,
    LoopTiming,
    ProcessSettings,
)
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_dob.teleop.slave import SlaveController, SlaveImpedance
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.topics import EFFORT_COMMAND, JOINT_STATES, POSE_DESIRED
from haptic_msgs_py.values import EffortCommand, JointSample, StampedVector


def slave_controller_node_specs() -> list[ParamSpec]:
    """Every parameter of the slave controller node."""
    return [
        *specs_of(LoopTiming),
        *specs_of(LoopInputs),
        *specs_of(CommandOutputSettings),
        *specs_of(ProcessSettings),
        *model_specs(),
        *specs_of(SlaveImpedance, "slave.", read_only=True),
    ]


class SlaveControllerNode(LoopNode):
    """Tracks ``pose_desired`` with the slave's joint impedance (``SlaveController``)."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "slave_controller_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(
            name, specs=slave_controller_node_specs(), context=context, namespace=namespace
        )
        v = self.params.values
        model = build_model(v)
        self.controller = SlaveController(
            model, build(SlaveImpedance, v, "slave."), round(1e9 / v["rate_hz"]) * 1e-9
        )
        self.joints = JointMap(model.joint_names)
        self._q: tuple[int, list[float], list[float]] | None = None
        self._target: StampedVector | None = None
        self._last: EffortCommand | None = None
        self._first_ns: int | None = None  # the first sample's stamp (a trajectory's t = 0)
        self._token = v["command_token"] or new_token()
        self._pub = LoopPublisher(self, EFFORT_COMMAND, codecs.EFFORT, qos.LOOP)
        inputs = qos.loop_input(v["input_reliability"])
        # first: the command goes out before the observer's estimate is made (timing.md)
        on_joints, on_target = self._on_joints, self._on_target
        LoopSubscription(self, JOINT_STATES, codecs.JOINT_STATE, on_joints, inputs, first=True)
        if self.controller.trajectory is None:
            LoopSubscription(self, POSE_DESIRED, codecs.POSE, on_target, inputs, first=True)
        self.diagnostics = Diagnostics(self, self._report)

    def _on_joints(self, js: JointSample) -> None:
        try:
            idx = self.joints.index(js.name, len(js.position))
            n = len(js.name) or len(js.position)
            q = pick(js.position, idx, "position", n)
            qd = pick(js.velocity, idx, "velocity", n)
        except ValueError as exc:
            self.log.error(f"ignoring joint_states: {exc}", throttle_duration_sec=5.0)
            return
        self._q = (js.stamp_ns, q, qd)
        self._step()

    def _on_target(self, target: StampedVector) -> None:
        self._target = target
        self._step()

    def _step(self) -> None:
        joints, target = self._q, self._target
        playing = self.controller.trajectory is not None
        if joints is None or not (playing or (target is not None and joints[0] == target.stamp_ns)):
            return
        k = joints[0]
        last = self._last
        if last is not None and k <= (last.stamp_ns or 0):
            if k == last.stamp_ns:
                self._pub.publish(last)  # the same sample again: the same command
            return
        _, q, qd = joints
        if playing:
            self._first_ns = k if self._first_ns is None else self._first_ns
            tau = self.controller.play(np.asarray(q), np.asarray(qd), (k - self._first_ns) * 1e-9)
        else:
            assert target is not None
            tau = self.controller.command(np.asarray(q), np.asarray(qd), target.vector)
        self._last = EffortCommand(k, tuple(tau), self._token)
        self._pub.publish(self._last)
        self.diagnostics.tick()

    def next_sample_ns(self) -> int | None:
        """No parameter changes at run time (all read-only)."""
        return None

    def _report(self) -> Report:
        values = {"commands": self.diagnostics.cycles}
        playing = self.controller.trajectory is not None
        if self.diagnostics.rate_hz == 0.0:
            what = "joint_states" if playing else "joint_states/pose_desired pairs"
            return WARN, f"no {what} in the last second", values
        return OK, "playing the trajectory" if playing else "tracking", values


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob slave_controller_node``."""
    return main_for(SlaveControllerNode, args, slave_controller_node_specs())


if __name__ == "__main__":
    sys.exit(main())
