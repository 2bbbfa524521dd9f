"""environment_node: the virtual wall. ee_pose + ee_twist of sample k -> wrench_desired k.

The wall (``stiffness_n_per_m``, ``damping_n_s_per_m``, ``position``, ``normal``, ``two_sided``)
and a known force it adds at the sample's time (``excitation.*``: a step or a sine along its
normal, a chirp or a multisine along it or along each axis, and a holding spring: the
identification experiment's input) change at run time. The sample's time counts from the first
sample the node rendered: sample 0 in lockstep (stamp 0), and in real time, where a stamp is the
system clock's, the first that came (a restarted node starts its excitation anew).
"""

from __future__ import annotations

import sys
from collections.abc import Mapping
from typing import Any, NamedTuple

from rclpy.context import Context

from haptic_dob.core.cycle import wall_force
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.nodes.common import main_for
from haptic_dob.nodes.settings import LoopInputs, LoopTiming, ProcessSettings
from haptic_dob.runtime.params import ParamSpec, build, specs_of
from haptic_dob.runtime.ros.diagnostics import OK, WARN, Diagnostics, Report
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros import qos
from haptic_msgs_py.ros.loop_io import LoopPublisher, LoopSubscription
from haptic_msgs_py.stamps import period_ns
from haptic_msgs_py.topics import EE_POSE, EE_TWIST, WRENCH_DESIRED
from haptic_msgs_py.values import StampedVector


def environment_node_specs() -> list[ParamSpec]:
    """Every parameter of the environment node (the wall and the excitation change at run time)."""
    return [
        *specs_of(LoopTiming),
        *specs_of(LoopInputs),
        *specs_of(ProcessSettings),
        *specs_of(VirtualWall),
        *specs_of(Excitation, "excitation."),
    ]


class Environment(NamedTuple):
    """What the node renders: the wall and the excitation it adds."""

    wall: VirtualWall
    excitation: Excitation


class EnvironmentNode(LoopNode):
    """Renders a wall (or a two-sided spring) and a known excitation; both change at run time."""

    def __init__(
        self,
        context: Context | None = None,
        name: str = "environment_node",
        namespace: str | None = None,
    ) -> None:
        super().__init__(name, specs=environment_node_specs(), context=context, namespace=namespace)
        self.wall, self.excitation = self._settings(self.params.values)
        self._adds = self.excitation if self.excitation.active else None  # what wall_force adds
        self._pose: StampedVector | None = None
        self._twist: StampedVector | None = None
        self._period_ns = period_ns(self.params.values["rate_hz"])
        self._emitted_ns = -1  # stamp of the newest wall force
        self._origin_ns: int | None = None  # stamp of the first sample rendered: time 0
        self._pub = LoopPublisher(
            self, WRENCH_DESIRED, codecs.WRENCH, qos.LOOP, self.params.values["base_frame"]
        )
        inputs = qos.loop_input(self.params.values["input_reliability"])
        LoopSubscription(self, EE_POSE, codecs.POSE, self._on_pose, inputs)
        LoopSubscription(self, EE_TWIST, codecs.TWIST, self._on_twist, inputs)
        self.diagnostics = Diagnostics(self, self._report)
        self.params.set_validator(self._settings, self._apply)

    def _report(self) -> Report:
        w = self.wall
        values = {
            "stiffness_n_per_m": w.stiffness_n_per_m,
            "damping_n_s_per_m": w.damping_n_s_per_m,
            "position": list(w.position),
            "normal": list(w.normal),
            "two_sided": w.two_sided,
            "excitation": self.excitation.label(),
        }
        if self.diagnostics.rate_hz == 0.0:
            return WARN, "no ee_pose/ee_twist pairs in the last second", values
        return OK, "rendering", values

    def next_sample_ns(self) -> int | None:
        """The pose after the newest rendered is the first rendered with a changed wall."""
        last = self._emitted_ns
        return None if last < 0 else last + self._period_ns

    @staticmethod
    def _settings(values: Mapping[str, Any]) -> Environment:
        return Environment(build(VirtualWall, values), build(Excitation, values, "excitation."))

    def _apply(self, env: Environment) -> None:
        self.wall, self.excitation = env
        self._adds = env.excitation if env.excitation.active else None
        self.log.info(f"wall now {env.wall}, excitation {env.excitation.label()}")

    def _on_pose(self, pose: StampedVector) -> None:
        self._pose = pose
        twist = self._twist
        if twist is not None and twist.stamp_ns == pose.stamp_ns:
            self._emit(pose, twist)

    def _on_twist(self, twist: StampedVector) -> None:
        self._twist = twist
        pose = self._pose
        if pose is not None and pose.stamp_ns == twist.stamp_ns:
            self._emit(pose, twist)

    def _emit(self, pose: StampedVector, twist: StampedVector) -> None:
        self._emitted_ns = stamp = pose.stamp_ns
        if self._origin_ns is None:
            self._origin_ns = stamp
        force = wall_force(
            self.wall, pose.vector, twist.vector, self._adds, stamp - self._origin_ns
        )
        self._pub.publish(StampedVector(pose.stamp_ns, force))
        self.diagnostics.tick()


def main(args: list[str] | None = None) -> int:
    """``ros2 run haptic_dob environment_node``."""
    return main_for(EnvironmentNode, args, environment_node_specs())


if __name__ == "__main__":
    sys.exit(main())
