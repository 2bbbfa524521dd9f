"""channel_node: one end of the teleoperation channel (``role`` master or slave).

Master end (``/master``): ``ee_pose`` + ``ee_twist`` of sample k and the slave's newest message
-> ``wrench_desired`` k (the master's controller renders it as its wall) and the message of
sample k to the slave. Slave end (``/slave``): ``ee_pose`` + ``ee_twist`` + the contact force
(``wrench_estimate``, or ``wrench_measured`` with ``teleop.force_source: sensor``) of sample k
and the master's newest message -> ``pose_desired`` k (the point the slave's controller tracks)
and the message of sample k to the master. The ends talk on ``/teleop/to_slave`` and
``/teleop/to_master`` (reliable, in order); each applies the channel's delay, jitter and loss to
what it receives, and the passivity control to its port (``haptic_dob.teleop.ends``).

``wait_for_peer`` (lockstep): sample k waits for the peer's samples up to ``k - delay``, so the
graph reproduces the batch run (a peer that stalls stalls the loop); off (real time), it uses
what has come. A sample answered already is answered again with the same output (a re-send).
"""

from __future__ import annotations

import sys
from typing import Any

from rclpy.context import Context

from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.core.models.slide import SlideModel
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.settings import ChannelEnd, LoopInputs, LoopTiming, ProcessSettings
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_dob.teleop.ends import MasterEnd, PortMessage, SlaveEnd, Vec3
from haptic_dob.teleop.graph import TO_MASTER, TO_SLAVE
from haptic_dob.teleop.settings import ChannelSettings, TeleopSettings
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.topics import (
    EE_POSE,
    EE_TWIST,
    POSE_DESIRED,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)
from haptic_msgs_py.values import JointSample, StampedVector

PORT_NAMES = ("x", "y", "z", "energy", "silent")


def to_wire(m: PortMessage) -> JointSample:
    """A port message as a JointState: the point, velocity and force as joints x, y, z; the
    energy book as joint ``energy`` (position E_in, velocity E_out, effort dissipated, J); and
    ``silent`` (position 1.0 when the sender found its peer silent)."""
    s = 1.0 if m.peer_silent else 0.0
    return JointSample(
        m.stamp_ns,
        PORT_NAMES,
        (*m.position, m.energy_in_j, s),
        (*m.velocity, m.energy_out_j, 0.0),
        (*m.force, m.dissipated_j, 0.0),
    )


def from_wire(js: JointSample) -> PortMessage:
    """The port message a JointState of ``to_wire`` carries."""
    p, v, f = js.position, js.velocity, js.effort
    return PortMessage(
        js.stamp_ns,
        (p[0], p[1], p[2]),
        (v[0], v[1], v[2]),
        (f[0], f[1], f[2]),
        p[3],
        v[3],
        f[3],
        p[4] != 0.0,
    )


def channel_node_specs() -> list[ParamSpec]:
    """Every parameter of the channel node."""
    return [
        *specs_of(LoopTiming),
        *specs_of(LoopInputs),
        *specs_of(ProcessSettings),
        *model_specs(),
        *specs_of(ChannelEnd),
        *specs_of(TeleopSettings, "teleop.", read_only=True),
        *specs_of(ChannelSettings, "channel.", read_only=True),
    ]


class ChannelNode(LoopNode):
    """One end of the teleoperation channel (``haptic_dob.teleop.ends`` on the ROS graph)."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "channel_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=channel_node_specs(), context=context, namespace=namespace)
        v = self.params.values
        teleop = build(TeleopSettings, v, "teleop.")
        channel = build(ChannelSettings, v, "channel.")
        period = round(1e9 / v["rate_hz"])
        self.role: str = v["role"]
        self.wait = bool(v["wait_for_peer"])
        master = self.role == "master"
        peer = "slave" if master else "master"
        log = self.log

        def lost(why: str) -> None:
            log.warning(f"nothing from the {peer} for {why}: {self._fallback()}")

        def back() -> None:
            log.info(f"the {peer} is back")

        self.end: MasterEnd | SlaveEnd
        if master:
            model = build_model(v)
            axis = tuple(float(a) for a in model.axis) if isinstance(model, SlideModel) else None
            self.end = MasterEnd(teleop, channel, period, axis, lost, back)  # type: ignore[arg-type]  # 3 floats
        else:
            self.end = SlaveEnd(teleop, channel, period, lost, back)
        frame = v["base_frame"]
        out, codec = (WRENCH_DESIRED, codecs.WRENCH) if master else (POSE_DESIRED, codecs.POSE)
        self._out = LoopPublisher(self, out, codec, qos.LOOP, frame)
        self._link = LoopPublisher(
            self, TO_SLAVE if master else TO_MASTER, codecs.JOINT_STATE, qos.LOOP
        )
        inputs = qos.loop_input(v["input_reliability"])
        LoopSubscription(self, EE_POSE, codecs.POSE, self._on_pose, inputs)
        LoopSubscription(self, EE_TWIST, codecs.TWIST, self._on_twist, inputs)
        if not master:
            force = WRENCH_MEASURED if teleop.force_source == "sensor" else WRENCH_ESTIMATE
            LoopSubscription(self, force, codecs.WRENCH, self._on_force, inputs)
        link_in = TO_MASTER if master else TO_SLAVE
        reliable = qos.loop_input("reliable")  # every message, in order: the delay line's draws
        LoopSubscription(self, link_in, codecs.JOINT_STATE, self._on_link, reliable)
        self._pose: StampedVector | None = None
        self._twist: StampedVector | None = None
        self._force: StampedVector | None = None
        self._done_ns = -1
        self._answer: Any = None
        self._tracked: tuple[int, Vec3, Vec3] | None = None  # the slave's, its force not here
        self.diagnostics = Diagnostics(self, self._report)

    def _fallback(self) -> str:
        return "rendering zero force" if self.role == "master" else "holding where the slave is"

    # --- inputs ----------------------------------------------------------------------------
    def _on_pose(self, pose: StampedVector) -> None:
        self._pose = pose
        self._step(sample=True)

    def _on_twist(self, twist: StampedVector) -> None:
        self._twist = twist
        self._step(sample=True)

    def _on_force(self, force: StampedVector) -> None:
        self._force = force  # a newer force than the sample's is not the sample again
        self._step(sample=self._pose is not None and force.stamp_ns == self._pose.stamp_ns)

    def _on_link(self, js: JointSample) -> None:
        self.end.receive(from_wire(js))
        self._step(sample=False)

    # --- the cycle -------------------------------------------------------------------------
    def _step(self, sample: bool) -> None:
        """Answer the newest sample once its inputs (and, in lockstep, the peer's) are here. In
        real time the slave's point to track goes out on its point alone unless the passivity
        controller needs the force (its controller's command then does not wait for the
        estimate), and its message to the master once the force came (``_finish``); in
        lockstep both wait for the force, so a lost estimate is made again for a re-sent
        sample."""
        tracked = self._tracked  # a sample awaiting its force goes first
        if tracked is not None:
            if not self._finish(tracked):
                if sample and self._pose is not None and self._pose.stamp_ns == tracked[0]:
                    self._out.publish(self._answer)  # the same sample again: the same answer
                return
            if not self._newer(tracked[0]):
                return
        pose, twist = self._pose, self._twist
        if pose is None or twist is None or pose.stamp_ns != twist.stamp_ns:
            return
        k = pose.stamp_ns
        if k <= self._done_ns:
            if k == self._done_ns and sample:  # the same sample again: the same answer
                self._out.publish(self._answer)
            return
        if self.wait and not self.end.ready(k):
            return  # the peer's message is on its way
        end = self.end
        if isinstance(end, MasterEnd):
            value, message = end.cycle(k, pose.vector, twist.vector)
            self._answer_with(k, value)
            self._send(k, message)
            return
        force = self._force.vector if self._force and self._force.stamp_ns == k else None
        if force is None and (end.target_needs_force or self.wait):
            return
        self._answer_with(k, end.track(k, pose.vector, force))
        self._tracked = (k, pose.vector, twist.vector)
        self._finish(self._tracked)

    def _finish(self, tracked: tuple[int, Vec3, Vec3]) -> bool:
        """The slave's sample tracked: its message once its force is here; skipped when a newer
        force came first (real time: its estimate was lost). Whether it is done with."""
        end, (k, position, velocity), force = self.end, tracked, self._force
        assert isinstance(end, SlaveEnd)
        if force is None or force.stamp_ns < k:
            return False  # its force is on its way
        self._tracked = None
        if force.stamp_ns > k:
            end.forget()
            self._done_ns = k
            return True
        self._send(k, end.message(k, position, velocity, force.vector))
        return True

    def _newer(self, k: int) -> bool:
        """A sample newer than ``k`` is here."""
        return self._pose is not None and self._pose.stamp_ns > k

    def _send(self, k: int, message: PortMessage) -> None:
        self._done_ns = k
        self._link.publish(to_wire(message))
        self.diagnostics.tick()

    def _answer_with(self, k: int, value: tuple[float, float, float]) -> None:
        """Sample k's answer to the local loop (the wall force, or the point to track)."""
        self._answer = StampedVector(k, value)
        self._out.publish(self._answer)

    def next_sample_ns(self) -> int | None:
        """No parameter changes at run time (all read-only)."""
        return None

    def _report(self) -> Report:
        end = self.end
        values = {
            "role": self.role,
            "delay_samples": end.line.delay,
            "peer": "silent" if end.peer_silent else "ok",
            "messages_lost": end.line.dropped,
            "energy_in_j": end.port.e_in,
            "energy_out_j": end.port.e_out,
            "dissipated_j": end.port.dissipated_j,
        }
        if end.peer_silent:
            return WARN, f"peer silent: {self._fallback()}", values
        if self.diagnostics.rate_hz == 0.0:
            return WARN, "no samples in the last second", values
        return OK, "relaying", values


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob channel_node``."""
    return main_for(ChannelNode, args, channel_node_specs())


if __name__ == "__main__":
    sys.exit(main())
