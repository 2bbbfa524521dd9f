"""The bridge's own settings: the safety it keeps and its run, and every parameter row.

``SafetySettings`` (``safety.*``: the clamp, the rate limit, the command watchdog, the dead-man)
and ``RunSettings`` (when the bridge starts and stops, what it writes) are frozen dataclasses
read by ``build`` (``runtime.params``); ``bridge_specs`` is the whole table with the driver's
``DriverProfile`` and groups (``driver_settings``). ``per_element`` spreads one value over every
command element.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from haptic_dob.bridge.driver_settings import PROFILES, CommandSettings, FrameSettings
from haptic_dob.bridge.state_settings import RELIABILITY, StateSettings
from haptic_dob.runtime.params import ParamSpec, param, specs_of

DEADMAN_TYPES = ("none", "bool", "joy")


@dataclass(frozen=True)
class SafetySettings:
    """What keeps the hand safe at the bridge (``safety.*``)."""

    command_limits: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description=("force clamp per command element, one value or one each; required"),
            unit="N",
            bounds=(0.0, 1e4),
            details=(
                "N (Cartesian) or N / N m (joints), before command.scale. [] refuses to start."
            ),
        ),
    )
    rate_limit: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [2000.0],
        metadata=param(
            description=(
                "largest change of each command element per second, one or one each; 0 = none"
            ),
            unit="N/s",
            bounds=(0.0, 1e7),
            details="A stop to zero is never slowed.",
        ),
    )
    command_timeout_s: float = field(
        default=0.005,
        metadata=param(
            description=("watchdog: zero command when the loop's command stopped for this long"),
            unit="s",
            bounds=(0.0005, 1.0),
            details="Counted in driver states.",
        ),
    )
    deadman: str = field(
        default="none",
        metadata=param(
            description=("dead-man input: none, a std_msgs/Bool topic or a sensor_msgs/Joy button"),
            choices=DEADMAN_TYPES,
            details="Force only while held; never seen = released.",
        ),
    )
    deadman_topic: str = field(default="", metadata=param(description="the dead-man's topic"))
    deadman_button: int = field(
        default=0,
        metadata=param(description="deadman joy: index of the button to hold", bounds=(0, 63)),
    )
    deadman_reliability: str = field(
        default="reliable",
        metadata=param(
            description="QoS reliability of the dead-man subscription", choices=RELIABILITY
        ),
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
            description=("loop nodes that must be up before the driver's states go to the loop"),
            read_only=True,
            details=("In this namespace, or fully qualified. Until then the driver gets zero."),
        ),
    )
    start_delay_s: float = field(
        default=0.5,
        metadata=param(
            description=(
                "settle time between the wait_for nodes being up and the first state handed on"
            ),
            unit="s",
            bounds=(0.0, 60.0),
            read_only=True,
        ),
    )
    duration_s: float = field(
        default=0.0,
        metadata=param(
            description=(
                "stop (zero command, exit) this long after the first state handed on; 0 = never"
            ),
            unit="s",
            bounds=(0.0, 1e6),
            read_only=True,
        ),
    )
    stats_file: str = field(
        default="",
        metadata=param(
            description="write the bridge's counts (JSON) here at shutdown",
            read_only=True,
            details="States, commands on time, refused, clamped, trips.",
        ),
    )
    external_torque_topic: str = field(
        default="",
        metadata=param(
            description=(
                "republish the observer's effort_estimate here, in the driver's joints; '' = off"
            ),
            read_only=True,
            details=(
                "As sensor_msgs/JointState (name and effort) in the driver's joint names and "
                "signs, as franka_ros2's external_joint_torques."
            ),
        ),
    )


@dataclass(frozen=True)
class DriverProfile:
    """The driver's kind (``profile``): the defaults of its ``state.*`` and ``command.*``."""

    profile: str = field(
        default=PROFILES[0],
        metadata=param(
            description="the driver's kind: the defaults of the command type, delay and effort",
            choices=PROFILES,
            read_only=True,
            details=(
                "ros2_control_effort: joint_state_broadcaster and an effort "
                "forward_command_controller. cartesian_wrench: a Touch-like Cartesian force input. "
                "suite: the suite's own contract."
            ),
        ),
    )


def bridge_specs() -> list[ParamSpec]:
    """The driver's, safety's and run's parameter rows (read-only: they define the session)."""
    return [
        *specs_of(DriverProfile),
        *specs_of(StateSettings, "state.", read_only=True),
        *specs_of(CommandSettings, "command.", read_only=True),
        *specs_of(FrameSettings, "frame.", read_only=True),
        *specs_of(SafetySettings, "safety.", read_only=True),
        *specs_of(RunSettings),
    ]


def per_element(
    name: str, values: Sequence[float], n: int, positive: bool, of: str = "command element"
) -> tuple[float, ...]:
    """One value for every one of ``n`` elements (each ``of``), or one each (``ValueError``
    otherwise)."""
    vals = tuple(float(v) for v in values)
    if len(vals) == 1:
        vals = vals * n
    if not vals:
        raise ValueError(f"{name}: set it (one value, or one per {of}); [] is none")
    if len(vals) != n:
        raise ValueError(f"{name} needs 1 or {n} values (one per {of}), got {len(vals)}")
    if positive and not all(v > 0.0 for v in vals):
        raise ValueError(f"{name} must be > 0, got {list(vals)}")
    return vals
