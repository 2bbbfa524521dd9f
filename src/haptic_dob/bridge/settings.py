"""The bridge's own settings: the safety it keeps and its run, and every parameter row.

``SafetySettings`` (``safety.*``: the clamp, the rate limit, the command watchdog, the dead-man)
and ``RunSettings`` (when the bridge starts and stops, what it writes) are frozen dataclasses
read by ``build`` (``runtime.params``); ``bridge_specs`` is the whole table with the driver's
groups (``driver_settings``). ``per_element`` spreads one value over every command element.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from haptic_dob.bridge.driver_settings import (
    PROFILES,
    RELIABILITY,
    CommandSettings,
    FrameSettings,
    StateSettings,
)
from haptic_dob.runtime.params import ParamSpec, param, specs_of

DEADMAN_TYPES = ("none", "bool", "joy")


@dataclass(frozen=True)
class SafetySettings:
    """What keeps the hand safe at the bridge (``safety.*``)."""

    command_limits: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            "force clamp per command element, N (Cartesian) or N / N m (joints), before "
            "command.scale: one value for every element or one each. Required: [] refuses to "
            "start",
            "N",
            0.0,
            1e4,
        ),
    )
    rate_limit: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [2000.0],
        metadata=param(
            "largest change of each command element per second (one value or one each); 0 = "
            "none. A stop to zero is never slowed",
            "N/s",
            0.0,
            1e7,
        ),
    )
    command_timeout_s: float = field(
        default=0.005,
        metadata=param(
            "watchdog: zero command when the loop's command stopped for this long, counted in "
            "driver states",
            "s",
            0.0005,
            1.0,
        ),
    )
    deadman: str = field(
        default="none",
        metadata=param(
            "dead-man input: none, a std_msgs/Bool topic or a sensor_msgs/Joy button; force "
            "only while held (never seen = released)",
            choices=DEADMAN_TYPES,
        ),
    )
    deadman_topic: str = field(default="", metadata=param("the dead-man's topic"))
    deadman_button: int = field(
        default=0, metadata=param("deadman joy: index of the button to hold", "", 0, 63)
    )
    deadman_reliability: str = field(
        default="reliable",
        metadata=param("QoS reliability of the dead-man subscription", choices=RELIABILITY),
    )

    def limits_for(self, n: int) -> tuple[float, ...]:
        """The clamp of each of ``n`` command elements (N or N m)."""
        return per_element("safety.command_limits", self.command_limits, n, positive=True)

    def rates_for(self, n: int) -> tuple[float, ...]:
        """The rate limit of each of ``n`` command elements (N/s; 0 = none)."""
        return per_element("safety.rate_limit", self.rate_limit, n, positive=False)

    def check(self) -> SafetySettings:
        """These settings, or ``ValueError`` naming what a session cannot go without."""
        if not self.command_limits:
            raise ValueError(
                "safety.command_limits: set the force clamp (N per axis, or N / N m per joint); "
                "the bridge does not start without one"
            )
        if self.deadman != "none" and not self.deadman_topic:
            raise ValueError(f"safety.deadman {self.deadman} needs safety.deadman_topic")
        return self


@dataclass(frozen=True)
class RunSettings:
    """When the bridge hands the driver's states to the loop, and when it stops."""

    wait_for: list[str] | tuple[str, ...] = field(
        default_factory=lambda: ["environment_node", "observer_node", "controller_node"],
        metadata=param(
            "loop nodes (in this namespace, or fully qualified) that must be up before the "
            "driver's states go to the loop; until then the driver gets zero",
            read_only=True,
        ),
    )
    start_delay_s: float = field(
        default=0.5,
        metadata=param(
            "settle time between the wait_for nodes being up and the first state handed on",
            "s",
            0.0,
            60.0,
            read_only=True,
        ),
    )
    duration_s: float = field(
        default=0.0,
        metadata=param(
            "stop (zero command, exit) this long after the first state handed on; 0 = never",
            "s",
            0.0,
            1e6,
            read_only=True,
        ),
    )
    stats_file: str = field(
        default="",
        metadata=param(
            "write the bridge's counts (JSON) here at shutdown: states, commands on time, "
            "refused, clamped, trips",
            read_only=True,
        ),
    )
    external_torque_topic: str = field(
        default="",
        metadata=param(
            "republish the observer's effort_estimate here as sensor_msgs/JointState (name and "
            "effort) in the driver's joint names and signs, as franka_ros2's "
            "external_joint_torques; '' = off",
            read_only=True,
        ),
    )


def bridge_specs() -> list[ParamSpec]:
    """The driver's, safety's and run's parameter rows (read-only: they define the session)."""
    profile = ParamSpec(
        "profile",
        PROFILES[0],
        "the driver's kind: ros2_control_effort (joint_state_broadcaster and an effort "
        "forward_command_controller), cartesian_wrench (a Touch-like Cartesian force input), "
        "suite (the suite's own contract)",
        choices=PROFILES,
        read_only=True,
    )
    return [
        profile,
        *specs_of(StateSettings, "state.", read_only=True),
        *specs_of(CommandSettings, "command.", read_only=True),
        *specs_of(FrameSettings, "frame.", read_only=True),
        *specs_of(SafetySettings, "safety.", read_only=True),
        *specs_of(RunSettings),
    ]


def per_element(name: str, values: Sequence[float], n: int, positive: bool) -> tuple[float, ...]:
    """One value for every one of ``n`` elements, or one each (``ValueError`` otherwise)."""
    vals = tuple(float(v) for v in values)
    if len(vals) == 1:
        vals = vals * n
    if not vals:
        raise ValueError(f"{name}: set it (one value, or one per command element); [] is none")
    if len(vals) != n:
        raise ValueError(f"{name} needs 1 or {n} values (one per command element), got {len(vals)}")
    if positive and not all(v > 0.0 for v in vals):
        raise ValueError(f"{name} must be > 0, got {list(vals)}")
    return vals
