"""What a driver speaks, as settings: its profile, state and command topics, joints and axes.

Parameter groups, each a frozen dataclass read by ``build`` (``runtime.params``): ``profile``,
``state.*`` (``state_settings.StateSettings``), ``command.*`` (``CommandSettings``) and
``frame.*`` (``FrameSettings``). ``DriverSettings.of`` gathers them and gives the settings left
empty (``''``, ``-1``) their profile's value, so a YAML names only what differs from the profile.
``docs/devices.md`` says what each means for each driver.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from haptic_dob.bridge.state_settings import RELIABILITY, StateSettings
from haptic_dob.runtime.params import build, param
from haptic_msgs_py.topics import EFFORT_COMMAND, JOINT_STATES

PROFILES = ("ros2_control_effort", "cartesian_wrench", "suite")
COMMAND_TYPES = ("float64_multi_array", "wrench_stamped", "wrench", "vector3")

#: each profile's command type, driver cycles before a command acts, and effort source
PROFILE_DEFAULTS: dict[str, tuple[str, int, str]] = {
    # ros2_control: a command that arrives during cycle k is written at cycle k+1
    "ros2_control_effort": ("float64_multi_array", 1, "commanded"),
    # Touch-like drivers: the device's own servo loop applies the newest force on arrival
    "cartesian_wrench": ("wrench_stamped", 0, "commanded"),
    # the suite's own device: command k held over [k, k+1), its joint_states carry that effort
    "suite": ("float64_multi_array", 0, "driver"),
}


@dataclass(frozen=True)
class CommandSettings:
    """The driver's command topic (``command.*``): type, QoS, order, units, timing."""

    topic: str = field(
        default="",
        metadata=param(
            description="the driver's command topic (<controller>/commands, force_feedback ...)"
        ),
    )
    type: str = field(
        default="",
        metadata=param(
            description=("the command's type: joint efforts, or a force; '' = the profile's"),
            choices=("", *COMMAND_TYPES),
            details=(
                "float64_multi_array: joint efforts; wrench_stamped, wrench or vector3: a force in "
                "the base frame."
            ),
        ),
    )
    reliability: str = field(
        default="reliable",
        metadata=param(
            description="QoS reliability of the publisher",
            choices=RELIABILITY,
            details=(
                "reliable serves both kinds of subscription (forward_command_controller's is "
                "reliable)."
            ),
        ),
    )
    depth: int = field(
        default=10, metadata=param(description="history depth of the publisher", bounds=(1, 1000))
    )
    joints: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            description=(
                "float64_multi_array: the controller's joints, in order; [''] = state.joints"
            ),
            details=(
                "The controller's joints parameter in its order (driver names); a joint the model "
                "lacks gets 0."
            ),
        ),
    )
    frame_id: str = field(
        default="",
        metadata=param(description="wrench_stamped: the header's frame_id; '' = base_frame"),
    )
    scale: float = field(
        default=1.0,
        metadata=param(description="driver command units per N (or N m)", bounds=(1e-9, 1e9)),
    )
    delay_samples: int = field(
        default=-1,
        metadata=param(
            description=(
                "driver cycles from a command's arrival to the cycle it acts in; -1 = profile's"
            ),
            bounds=(-1, 4),
            details=(
                "1 for ros2_control (written at its next update), 0 for a driver applying it on "
                "arrival."
            ),
        ),
    )


@dataclass(frozen=True)
class FrameSettings:
    """The driver's Cartesian axes against the model's base frame (``frame.*``)."""

    axes: list[int] | tuple[int, ...] = field(
        default_factory=lambda: [0, 1, 2],
        metadata=param(
            description="the driver's axis (0 x, 1 y, 2 z) of each model base axis",
            bounds=(0, 2),
            details="For the force command and the pose state.",
        ),
    )
    signs: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [1.0, 1.0, 1.0],
        metadata=param(
            description="+1 or -1 per model base axis: driver[axes[i]] = signs[i] * model[i]",
            bounds=(-1.0, 1.0),
        ),
    )


@dataclass(frozen=True)
class DriverSettings:
    """The driver's groups with the profile's values in place of the empty ones."""

    profile: str
    state: StateSettings
    command: CommandSettings
    frame: FrameSettings
    delay_samples: int  # driver cycles from a command's arrival to the cycle it acts in
    effort: str  # commanded | driver

    @property
    def cartesian(self) -> bool:
        """The command is a force in the base frame (else joint efforts)."""
        return self.command.type != "float64_multi_array"

    @classmethod
    def of(cls, values: Mapping[str, Any]) -> DriverSettings:
        """The settings in a node's values; ``ValueError`` naming what is missing or
        inconsistent."""
        profile = values.get("profile", PROFILES[0])
        if profile not in PROFILES:
            raise ValueError(f"profile must be one of {', '.join(PROFILES)}, got {profile!r}")
        state = build(StateSettings, values, "state.")
        command = build(CommandSettings, values, "command.")
        frame = build(FrameSettings, values, "frame.")
        kind, delay, effort = PROFILE_DEFAULTS[profile]
        if not command.type:
            command = replace(command, type=kind)
        out = cls(
            profile,
            state,
            command,
            frame,
            delay if command.delay_samples < 0 else command.delay_samples,
            state.effort or effort,
        )
        out.check()
        return out

    def check(self) -> None:
        """``ValueError`` for what cannot work together."""
        if not self.state.topic:
            raise ValueError("state.topic: name the driver's state topic (e.g. /fd/joint_states)")
        if not self.command.topic:
            raise ValueError(
                "command.topic: name the driver's command topic (e.g. /fd/fd_controller/commands)"
            )
        if self.profile == "cartesian_wrench" and not self.cartesian:
            raise ValueError("profile cartesian_wrench takes wrench_stamped, wrench or vector3")
        if self.profile != "cartesian_wrench" and self.cartesian:
            raise ValueError(
                f"profile {self.profile} commands joint efforts (float64_multi_array); a force "
                "command is profile cartesian_wrench"
            )
        if sorted(self.frame.axes) != [0, 1, 2] or len(self.frame.signs) != 3:
            raise ValueError("frame.axes must be a permutation of [0, 1, 2], with 3 frame.signs")
        if any(abs(s) != 1.0 for s in (*self.state.signs, *self.frame.signs)):
            raise ValueError("state.signs and frame.signs take +1 or -1 only")
        if self.state.type == "pose" and self.effort == "driver":
            raise ValueError("a pose state carries no effort: state.effort must be commanded")

    def check_apart(self, resolve: Callable[[str], str]) -> None:
        """``ValueError`` when the driver's state or command topic is the loop's own
        (``resolve``: a topic's name as the bridge's node resolves it)."""
        ours = {resolve(t) for t in (JOINT_STATES, EFFORT_COMMAND)}
        for topic in (self.state.topic, self.command.topic):
            if resolve(topic) in ours:
                raise ValueError(
                    f"the driver's {topic} is the loop's own topic here: run the loop in a "
                    "namespace of its own (-r __ns:=/haptic) and name the driver's topics "
                    "absolutely (/fd/joint_states)"
                )

    def describe(self) -> str:
        """One line: the profile, the state and the command topics with their types and QoS."""
        c, s = self.command, self.state
        return (
            f"a {self.profile} driver: state {s.topic} ({s.type}, {s.reliability}), "
            f"command {c.topic} ({c.type}, {c.reliability})"
        )
