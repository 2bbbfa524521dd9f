"""device_node: a simulated haptic device on the lab network, in lockstep or in real time.

Per sample k (stamped ``k * T`` in lockstep, the system clock in real time): ``ee_pose``,
``ee_twist``, ``joint_states`` (position, velocity, the effort applied over [k-1, k) after
saturation), ``wrench_measured`` (the handle sensor), and while read ``sim/hand_wrench`` (the
true hand force) and ``/clock``. Takes ``effort_command`` (Float64MultiArray in joint order).

- lockstep: sample 0 once the ``wait_for`` nodes are matched, k+1 after command k (k again after
  ``lockstep_timeout_s``), held while a recorder lags ``max_recorder_lag_s``; ends after
  ``duration_s`` (0: never) once the recorder has it all (docs/running.md, "Clock modes").
- realtime: ticks at ``rate_hz`` on the wall clock's grid, the newest valid command applied.

Safety on every path (docs/safety.md): efforts clamped to ``effort_limits``, a bad command counts
as zero, a watchdog (``command_timeout_s``), zero at shutdown; only its controller commands it.
"""

from __future__ import annotations

import sys
from collections.abc import Callable
from typing import Any

from rclpy.context import Context

from haptic_dob.nodes.command_input import CommandInput
from haptic_dob.nodes.common import main_for, missing_nodes
from haptic_dob.runtime.cpus import scheduling
from haptic_dob.runtime.ros.diagnostics import Diagnostics, Report, report_of
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher
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
from haptic_msgs_py.values import JointSample, Stamp, StampedVector
from haptic_sim.device.cycle_stats import CycleStats
from haptic_sim.device.factory import build_device
from haptic_sim.device.loop import DeviceLoop
from haptic_sim.device.report import device_status
from haptic_sim.device.sample import DeviceSample
from haptic_sim.device.settings import (
    DeviceLoopSettings,
    device_node_specs,
    start_topics,
)


class DeviceNode(LoopNode):
    """A simulated device stepping in the cycle contract (``DeviceLoop``) on the ROS graph."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "device_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=device_node_specs(), context=context, namespace=namespace)
        v = self.params.values
        self._start_with = start_topics(v["start_with"])
        self.device = build_device(v)
        self.dof = self.device.dof
        self.period_ns = self.device.period_ns
        self.lockstep = v["clock_mode"] == "lockstep"
        cycles = round(v["duration_s"] * v["rate_hz"])
        last_k = cycles if cycles > 0 else None  # the run ends after publishing sample N
        self.loop = DeviceLoop(self.device, self, self.log, v, self.lockstep, last_k)
        self.finishes_run = last_k is not None  # a process of two devices waits for both
        self.params.set_validator(self.loop.settings_for, self._apply)
        base = v["base_frame"]
        self._names = tuple(self.device.model.joint_names)

        def pub(topic: str, codec: codecs.Codec, on_demand: bool = False) -> LoopPublisher:
            return LoopPublisher(self, topic, codec, qos.LOOP, base, on_demand=on_demand)

        self._p_pose, self._p_twist = pub(EE_POSE, codecs.POSE), pub(EE_TWIST, codecs.TWIST)
        self._p_js = pub(JOINT_STATES, codecs.JOINT_STATE)
        self._p_measured = pub(WRENCH_MEASURED, codecs.WRENCH)
        # evaluation topics: sent only while someone listens
        self._p_hand = pub(HAND_WRENCH, codecs.WRENCH, on_demand=True)
        # the sample's stamp as ROS time, in both clock modes (in real time the system clock's):
        # tools with use_sim_time (ros2 bag record --use-sim-time, a node's -p
        # use_sim_time:=true) share the loop's time base
        self._p_clock = LoopPublisher(self, CLOCK, codecs.CLOCK, qos.CLOCK, on_demand=True)
        inputs = qos.loop_input(v["input_reliability"])
        self._sub = CommandInput(self, self.loop.command, inputs, v)
        self._bus = self._sub.bus
        # both modes: sample 0 waits for the recorders' readers to match; lockstep back-pressure
        raw_subscription(
            self, "std_msgs/msg/Header", RECORDER_PROGRESS, self._on_progress, qos.CLOCK
        )
        self.diagnostics = Diagnostics(self, self._report)
        mode = "lockstep" if self.lockstep else f"realtime at {v['rate_hz']:g} Hz"
        self.log.info(
            f"simulated {v['model']} device, {mode}, effort limits {list(self.limits)}, "
            f"scheduling {scheduling()}"
        )

    @property
    def limits(self) -> tuple[float, ...]:
        """The per-joint effort limits in force (N or N m)."""
        return self.loop.guard.limits

    def _apply(self, settings: DeviceLoopSettings) -> None:
        self.loop.configure(settings)
        self.log.info(f"effort limits now {list(self.limits)}")

    def _advance(self, effort: list[float]) -> None:
        """Command k moves the plant (``DeviceLoop.advance``)."""
        self.loop.advance(effort)

    # --- LoopPort: topics, deferred work, graph ---------------------------------------------
    def publish(self, s: DeviceSample) -> None:
        """Sample k to every topic, in the order that closes the loop soonest: the wall's inputs
        first. Nodes in this process get it at once, depth first: the sensor before the joints,
        so that in CL the command is out before the observer works. A device alone in its
        process sends the joints before the sensor: each DDS send costs tens of microseconds
        and in DOB (the suite's subject) the observer's joints are on the command's path.
        Readers in other processes get the sample once it is all out (``Bus.batch``)."""
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
            if self._p_clock.wanted:
                self._p_clock.publish(Stamp(k))
        finally:
            bus.end()

    def call_soon(self, work: Callable[[], None]) -> None:
        """Run ``work`` once this process's publishes under way have returned."""
        self._bus.call_soon(work)

    def waiting_for(self) -> str:
        """What the start still waits for ('' when nothing)."""
        wait_for = self.params.values["wait_for"]
        ns = self.get_namespace()
        missing = missing_nodes(wait_for, self.get_node_names_and_namespaces(), ns)
        if missing:
            return f"node{'s' if len(missing) > 1 else ''} {', '.join(missing)} in {ns}"
        for topic in self._start_with:  # a device to start with: built once it publishes
            if self.count_publishers(topic) < 1:
                return f"the device publishing {topic} (start_with)"
        for pub in self._bus.publishers():  # this node's and any composed with it
            if pub.readers < self.count_subscribers(pub.topic):
                return f"the subscribers of {pub.topic} to match"
        if wait_for and self._sub.get_publisher_count() < 1:
            return f"a publisher of {EFFORT_COMMAND}"
        return ""

    def recorders(self) -> int:
        """Publishers of recorder progress."""
        return self.count_publishers(RECORDER_PROGRESS)

    def cycled(self) -> None:
        """Count a cycle for the diagnostics' loop rate."""
        self.diagnostics.tick()

    def finish(self) -> None:
        """The run is over: the spin loop may stop."""
        self.finished = True

    def _on_progress(self, msg: Any) -> None:
        st = msg.stamp
        self.loop.progress(msg.frame_id, st.sec * NS_PER_S + st.nanosec)

    # --- time and end ------------------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        return self.loop.deadline

    def on_wakeup(self, now: float) -> None:
        self.loop.wakeup(now)

    def _report(self) -> Report:
        return report_of(device_status(self.loop, self._sub.report(), self._sub.refusing))

    def stats(self) -> CycleStats:
        """Real-time cycle statistics so far (what ``stats_file`` gets)."""
        return self.loop.stats()

    def on_shutdown(self) -> None:
        """Zero effort first; in real time one last period runs and is reported with it."""
        path = self.params.values["stats_file"]
        if path and not self.lockstep:
            self.stats().write(path)
        self.loop.shutdown()
        self.log.info("shutdown: effort zeroed")


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_sim device_node``."""
    return main_for(DeviceNode, args, device_node_specs())


if __name__ == "__main__":
    sys.exit(main())
