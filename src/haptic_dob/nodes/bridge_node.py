"""bridge_node: a foreign driver's topics in the loop in place of device_node (real time only).

Each driver state (``state.topic``: a ros2_control ``joint_states``, a Touch driver's position-
only ``joint_states``, a pose) goes to the loop as the suite's contract, stamped with the
driver's stamp: ``joint_states`` (the model's joints by name, velocity filled, the effort in force
over [k-1, k)), ``ee_pose`` and ``ee_twist`` (the model's kinematics). The loop's
``effort_command`` goes to the driver at once in its type and order (``command.topic``: a
forward command controller's ``Float64MultiArray``, a ``WrenchStamped``, ``Wrench`` or
``Vector3`` through ``J^-T``). Safety (``haptic_dob.bridge.loop``): the force clamp and rate
limit, a watchdog on the loop's command and one on the driver's state, the dead-man
(``safety.deadman``), nothing non-finite sent, and zero on every orderly exit. Profiles, settings
and recipes: docs/devices.md.
"""

from __future__ import annotations

import os
import sys
import time
from typing import Any

from rclpy.context import Context

from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.loop import BridgeLoop, Send
from haptic_dob.bridge.report import bridge_status, write_stats
from haptic_dob.bridge.settings import RunSettings, SafetySettings, bridge_specs
from haptic_dob.bridge.start import StartGate
from haptic_dob.bridge.state import StateReader, check_cartesian
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.nodes.command_input import CommandInput
from haptic_dob.nodes.common import main_for, missing_nodes
from haptic_dob.nodes.settings import (
    RELIABLE_INPUTS,
    CommandInputSettings,
    LoopInputs,
    LoopTiming,
    ProcessSettings,
)
from haptic_dob.runtime.discovery import exposure_warning
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import Diagnostics, Report, report_of
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.driver_wire import (
    COMMAND_TYPENAMES,
    DEADMAN_TYPENAMES,
    STATE_TYPENAMES,
    command_encoder,
    deadman_reader,
)
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.driver_io import driver_publisher, driver_subscription
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.topics import EE_POSE, EE_TWIST, EFFORT_ESTIMATE, JOINT_STATES
from haptic_msgs_py.values import EffortCommand, JointSample, StampedVector


def bridge_node_specs() -> list[ParamSpec]:
    """Every parameter of the bridge node."""
    return [
        *specs_of(LoopTiming),
        *specs_of(LoopInputs, defaults=RELIABLE_INPUTS),
        *specs_of(CommandInputSettings),
        *specs_of(ProcessSettings),
        *model_specs(),
        *bridge_specs(),
    ]


class BridgeNode(LoopNode):
    """A foreign driver in the loop (``BridgeLoop`` on the ROS graph)."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "bridge_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=bridge_node_specs(), context=context, namespace=namespace)
        v = self.params.values
        self.model = build_model(v)
        driver = DriverSettings.of(v)
        safety = build(SafetySettings, v, "safety.").check()
        self.run = build(RunSettings, v)
        self.reader = StateReader(
            driver.state, driver.frame, self.model.joint_names, 1 / v["rate_hz"]
        )
        driver.check_apart(self.resolve_topic_name)
        if self.reader.pose:
            check_cartesian(self.model)
        self._news: list[str] = []
        joints = self.reader.driver_joints
        self.loop = BridgeLoop(driver, safety, self.model, joints, v["rate_hz"], self._news.append)
        self.gate = StartGate(self.run.start_delay_s, self.run.duration_s, time.monotonic())
        self.finishes_run = self.run.duration_s > 0.0
        self._bad_state = ""
        base = v["base_frame"]
        self._p_pose = LoopPublisher(self, EE_POSE, codecs.POSE, qos.LOOP, base)
        self._p_twist = LoopPublisher(self, EE_TWIST, codecs.TWIST, qos.LOOP, base)
        self._p_js = LoopPublisher(self, JOINT_STATES, codecs.JOINT_STATE, qos.LOOP, base)
        self._names = tuple(self.model.joint_names)
        inputs = qos.loop_input(v["input_reliability"])
        self._commands = CommandInput(self, self.admit, inputs, v)
        self._bus = self._commands.bus
        # the driver's side: its own types, topics and QoS; a QoS mismatch is said, not silent
        c, s = driver.command, driver.state
        self._encode = command_encoder(c.type, c.frame_id or base)
        say = self._mismatch
        typename = COMMAND_TYPENAMES[c.type]
        self._send_bytes = driver_publisher(self, typename, c.topic, c.reliability, c.depth, say)
        self._decode: Any = (codecs.POSE if self.reader.pose else codecs.JOINT_STATE).decoder()
        self._on_receipt = s.stamp == "receipt"
        typename = STATE_TYPENAMES[s.type]
        driver_subscription(self, typename, s.topic, self._on_state, s.reliability, s.depth, say)
        if safety.deadman != "none":
            self._held = deadman_reader(safety.deadman, safety.deadman_button)
            typename, topic = DEADMAN_TYPENAMES[safety.deadman], safety.deadman_topic
            reliability = safety.deadman_reliability
            driver_subscription(self, typename, topic, self._on_deadman, reliability, 10, say)
        if self.run.external_torque_topic:  # the estimate in the driver's names, after the command
            topic = self.run.external_torque_topic
            self._p_ext = LoopPublisher(self, topic, codecs.JOINT_STATE, qos.LOOP, base)
            LoopSubscription(
                self, EFFORT_ESTIMATE, codecs.JOINT_STATE, self._on_estimate, qos.ESTIMATOR_IN
            )
        self.diagnostics = Diagnostics(self, self._report)
        unsent = self.loop.map.unsent
        self.log.info(
            f"bridge to {driver.describe()}, model {v['model']} {list(self._names)}"
            + (f"; not commanded: {list(unsent)}" if unsent else "")
        )
        exposed = exposure_warning(os.environ)
        if exposed:
            self.log.warning(exposed)

    def _mismatch(self, text: str) -> None:
        self.log.error(text, throttle_duration_sec=5.0)

    # --- the cycle: driver state -> loop -> driver command ------------------------------------
    def _on_state(self, data: bytes) -> None:
        now, now_ns = time.monotonic(), time.time_ns()
        try:
            m = self._decode(data)
            stamp = now_ns if self._on_receipt else m.stamp_ns
            if self.reader.pose:
                state = self.reader.position(stamp, m.vector)
            else:
                state = self.reader.joints(stamp, m.name, m.position, m.velocity, m.effort)
            sample, zero = self.loop.on_state(state, now, now_ns)
        except ValueError as exc:
            if str(exc) != self._bad_state:  # once per distinct problem, not at 1 kHz
                self.log.error(f"ignoring the driver's state: {exc}")
                self._bad_state = str(exc)
            return
        self._send(zero)
        if sample is not None:
            k, bus = sample.stamp_ns, self._bus
            bus.begin()  # composed, the loop's command comes back inside these publishes
            try:
                self._p_pose.publish(StampedVector(k, sample.ee_position))
                self._p_twist.publish(StampedVector(k, sample.ee_velocity))
                self._p_js.publish(JointSample(k, self._names, sample.q, sample.qd, sample.effort))
            finally:
                bus.end()
            self.diagnostics.tick()
        self._bad_state = ""
        self._say()

    def admit(self, cmd: EffortCommand) -> None:
        """Every command the command authority lets through (the loop's own controller's)."""
        self._send(self.loop.on_command(cmd, time.monotonic()))
        self.loop.book()  # off the command's path: after its send

    def _send(self, send: Send | None) -> None:
        if send is not None:
            self._send_bytes(self._encode(send.stamp_ns, send.values))

    def _on_deadman(self, data: bytes) -> None:
        self._send(self.loop.on_deadman(self._held(data), time.monotonic()))
        self._say()

    def _on_estimate(self, js: JointSample) -> None:
        """The observer's joint estimate in the driver's joint names and signs."""
        effort = tuple(s * e for s, e in zip(self.reader.signs, js.effort, strict=True))
        self._p_ext.publish(JointSample(js.stamp_ns, self.reader.driver_joints, (), (), effort))

    def _say(self) -> None:
        """What the loop and the state reader said during the cycle, once its command is out."""
        news, self._news[:] = [*self._news, *self.reader.count_warnings()], []
        for line in news:
            self.log.warning(line)

    # --- time: the start, the state watchdog, the end -------------------------------------------
    def next_wakeup(self) -> float | None:
        if not self.loop.started:
            return self.gate.poll_at
        due = [d for d in (self.loop.state_deadline, self.gate.end) if d is not None]
        return min(due) if due else None

    def on_wakeup(self, now: float) -> None:
        if not self.loop.started:
            if self.gate.look(now, self.waiting_for()):
                self.loop.start()
                self.log.info("the loop is up: the driver's states go to it")
            return
        end = self.gate.end
        if end is not None and now >= end:
            self.log.info(f"finished: {self.run.duration_s:g} s handed on")
            self.finished = True
            return
        self._send(self.loop.on_wakeup(now))
        self._say()

    def waiting_for(self) -> str:
        """What the start still waits for ('' when nothing)."""
        graph = self.get_node_names_and_namespaces()
        missing = missing_nodes(self.run.wait_for, graph, self.get_namespace())
        if missing:
            self.log.info(f"waiting for node(s) {', '.join(missing)}", throttle_duration_sec=5.0)
            return ", ".join(missing)
        for pub in self._bus.publishers():
            if pub.readers < self.count_subscribers(pub.topic):
                return f"the subscribers of {pub.topic} to match"
        return ""

    def _report(self) -> Report:
        return report_of(bridge_status(self.loop, self._commands.report(), self._commands.refusing))

    def on_shutdown(self) -> None:
        """Zero to the driver first (acknowledged before the process ends, when reliable)."""
        self._send(self.loop.stop(time.monotonic()))
        self.log.info("shutdown: zero command sent to the driver")
        if self.run.stats_file:
            write_stats(self.run.stats_file, self.loop.counts())


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob bridge_node``."""
    return main_for(BridgeNode, args, bridge_node_specs())


if __name__ == "__main__":
    sys.exit(main())
