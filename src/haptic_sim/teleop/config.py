"""A teleoperation session's configuration: one ``ros__parameters`` YAML for both sides, read
as the node graph reads it (sections by namespace: ``haptic_dob.teleop.graph``).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from haptic_dob.core.control import ImpedanceLaw
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.base import DeviceModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.runtime.params import build
from haptic_dob.teleop.graph import NAMESPACES, check_sections, load_teleop_sections, node_values
from haptic_dob.teleop.settings import ChannelSettings, TeleopSettings
from haptic_dob.teleop.slave import SlaveImpedance
from haptic_sim.arm.device import SimulatedArm
from haptic_sim.device.factory import NO_CONTACT, SimulatedDeviceKind, build_device
from haptic_sim.slide.session import LoopSettings


@dataclass(frozen=True)
class TeleopConfig:
    """Everything a teleoperation session needs: the parameter sections and what they give.

    Build with ``from_yaml`` or ``from_sections``; ``override`` gives a copy with parameters of
    one section changed (as ``haptic-launch --set`` does in the graph).
    """

    sections: Mapping[str, Mapping[str, Any]]
    loop: LoopSettings  # the master's device: rate, sub-steps, length, seed
    slave_loop: LoopSettings
    master_law: ImpedanceLaw
    master_observer: ObserverSettings
    slave_observer: ObserverSettings
    slave: SlaveImpedance
    contact: VirtualWall
    teleop: TeleopSettings
    channel: ChannelSettings

    def values(self, ns: str, node: str) -> dict[str, Any]:
        """Node ``/<ns>/<node>``'s parameters."""
        return node_values(self.sections, ns, node)

    @classmethod
    def from_sections(cls, sections: Mapping[str, Mapping[str, Any]]) -> TeleopConfig:
        """Check and build (``ValueError`` with the first problem)."""
        check_sections(sections)
        secs = {k: dict(v) for k, v in sections.items()}

        def of(ns: str, node: str) -> dict[str, Any]:
            return node_values(secs, ns, node)

        m_dev, s_dev = of("master", "device_node"), of("slave", "device_node")
        if s_dev.get("model", "slide") not in ("urdf", "phantom"):
            raise ValueError("the slave is an arm: /slave/device_node needs model urdf or phantom")
        ends = [
            (
                build(TeleopSettings, of(ns, "channel_node"), "teleop."),
                build(ChannelSettings, of(ns, "channel_node"), "channel."),
            )
            for ns in NAMESPACES
        ]
        if ends[0] != ends[1]:
            raise ValueError(
                "the two channel_node ends have different teleop.* or channel.* settings: "
                "set them in /**/channel_node"
            )
        loop, slave_loop = build(LoopSettings, m_dev), build(LoopSettings, s_dev)
        if loop.rate_hz != slave_loop.rate_hz or loop.duration_s != slave_loop.duration_s:
            raise ValueError("master and slave devices need the same rate_hz and duration_s")
        contact = build(VirtualWall, {**NO_CONTACT, **s_dev}, "contact.")
        master_law = build(ImpedanceLaw, of("master", "controller_node"))
        if ends[0][0].master_max_force_n != master_law.max_force_n:
            raise ValueError(
                f"teleop.master_max_force_n ({ends[0][0].master_max_force_n:g} N) must be the "
                f"master controller's max_force_n ({master_law.max_force_n:g} N): the channel "
                "books what the master can render"
            )
        return cls(
            sections=secs,
            loop=loop,
            slave_loop=slave_loop,
            master_law=master_law,
            master_observer=build(ObserverSettings, of("master", "observer_node")),
            slave_observer=build(ObserverSettings, of("slave", "observer_node")),
            slave=build(SlaveImpedance, of("slave", "slave_controller_node"), "slave."),
            contact=contact,
            teleop=ends[0][0],
            channel=ends[0][1],
        )

    @classmethod
    def from_yaml(cls, path: str | Path) -> TeleopConfig:
        """Load a teleoperation ``ros__parameters`` YAML file."""
        return cls.from_sections(load_teleop_sections(path))

    def override(self, changes: Mapping[str, Mapping[str, Any]]) -> TeleopConfig:
        """A copy with parameters set, by section (``{"/**/channel_node": {"channel.passivity":
        True}, "/master/device_node": {...}}``): what ``haptic-launch --set`` does to the graph."""
        secs = {k: dict(v) for k, v in self.sections.items()}
        for section, values in changes.items():
            secs.setdefault(section, {}).update(values)
        return TeleopConfig.from_sections(secs)

    def master_device(self) -> SimulatedDeviceKind:
        """The simulated master (slide, point mass or PHANToM, with its hand)."""
        return build_device(self.values("master", "device_node"))

    def slave_device(self) -> SimulatedArm:
        """The simulated slave arm, touching ``contact``."""
        device = build_device(self.values("slave", "device_node"))
        assert isinstance(device, SimulatedArm)  # from_sections refused a slide
        return device

    def model(self, ns: str, node: str) -> DeviceModel:
        """The model node ``/<ns>/<node>`` assumes (an observer's, a controller's)."""
        return build_model(self.values(ns, node))
