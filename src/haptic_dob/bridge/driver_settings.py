"""What a driver speaks, as settings: its profile, state and command topics, joints and axes.

Parameter groups, each a frozen dataclass read by ``build`` (``runtime.params``): ``profile``,
``state.*`` (``StateSettings``), ``command.*`` (``CommandSettings``) and ``frame.*``
(``FrameSettings``). ``DriverSettings.of`` gathers them and gives the settings left empty
(``''``, ``-1``) their profile's value, so a YAML names only what differs from the profile.
``docs/devices.md`` says what each means for each driver.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field, replace
from typing import Any

from haptic_dob.runtime.params import build, param

PROFILES = ("ros2_control_effort", "cartesian_wrench", "suite")
STATE_TYPES = ("joint_states", "pose")
COMMAND_TYPES = ("float64_multi_array", "wrench_stamped", "wrench", "vector3")
RELIABILITY = ("reliable", "best_effort")
VELOCITY_SOURCES = ("auto", "driver", "difference")
EFFORT_SOURCES = ("commanded", "driver")
STAMP_SOURCES = ("driver", "receipt")

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
class StateSettings:
    """The driver's state topic (``state.*``) and how its values become the model's."""

    topic: str = field(
        default="",
        metadata=param(
            "the driver's state topic (absolute, or relative to the bridge's namespace); not "
            "the loop's own joint_states"
        ),
    )
    type: str = field(
        default="joint_states",
        metadata=param(
            "sensor_msgs/JointState, or geometry_msgs/PoseStamped (a Cartesian model only: q is "
            "the tip's position)",
            choices=STATE_TYPES,
        ),
    )
    reliability: str = field(
        default="reliable",
        metadata=param(
            "QoS reliability of the subscription: reliable matches reliable publishers only "
            "(joint_state_broadcaster), best_effort matches both (SensorDataQoS drivers)",
            choices=RELIABILITY,
        ),
    )
    depth: int = field(default=10, metadata=param("queue depth of the subscription", "", 1, 1000))
    stamp: str = field(
        default="driver",
        metadata=param(
            "the stamp the loop's samples carry: the driver's header stamp, or the system clock "
            "when the state arrives (receipt: for a driver whose stamps are zero or do not "
            "advance)",
            choices=STAMP_SOURCES,
        ),
    )
    joints: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            "the driver's name of each model joint, in the model's joint order ([''] = the "
            "model's names); other joints in the state (grippers, a gimbal) are ignored"
        ),
    )
    signs: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [1.0],
        metadata=param(
            "+1 or -1 per model joint (one value: every joint): model q = sign * scale * driver "
            "q; efforts and commands alike",
            "",
            -1.0,
            1.0,
        ),
    )
    scale: float = field(
        default=1.0,
        metadata=param(
            "the driver's position unit in m or rad (0.001 for mm); velocities alike",
            "",
            1e-9,
            1e9,
        ),
    )
    velocity: str = field(
        default="auto",
        metadata=param(
            "joint velocity handed on: the driver's (driver), the backward difference of the "
            "positions low-passed at velocity_cutoff_hz (difference), or the driver's where its "
            "state has one (auto)",
            choices=VELOCITY_SOURCES,
        ),
    )
    velocity_cutoff_hz: float = field(
        default=100.0,
        metadata=param(
            "cutoff of the first-order low-pass on the differenced velocity; 0 = unfiltered",
            "Hz",
            0.0,
            1e5,
        ),
    )
    effort: str = field(
        default="",
        metadata=param(
            "effort of [k-1, k) in the loop's joint_states: what the bridge commanded "
            "(commanded) or what the driver reports (driver); '' = the profile's",
            choices=("", *EFFORT_SOURCES),
        ),
    )
    timeout_s: float = field(
        default=0.01,
        metadata=param(
            "watchdog: zero command when no driver state came for this long (wall clock); a "
            "stale state is not rendered",
            "s",
            0.001,
            1.0,
        ),
    )


@dataclass(frozen=True)
class CommandSettings:
    """The driver's command topic (``command.*``): type, QoS, order, units, timing."""

    topic: str = field(
        default="",
        metadata=param("the driver's command topic (<controller>/commands, force_feedback ...)"),
    )
    type: str = field(
        default="",
        metadata=param(
            "float64_multi_array (joint efforts), wrench_stamped, wrench or vector3 (a force in "
            "the base frame); '' = the profile's",
            choices=("", *COMMAND_TYPES),
        ),
    )
    reliability: str = field(
        default="reliable",
        metadata=param(
            "QoS reliability of the publisher: reliable serves both kinds of subscription "
            "(forward_command_controller's is reliable)",
            choices=RELIABILITY,
        ),
    )
    depth: int = field(default=10, metadata=param("history depth of the publisher", "", 1, 1000))
    joints: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            "float64_multi_array: the controller's joints parameter in its order (driver names; "
            "a joint the model lacks gets 0); [''] = state.joints"
        ),
    )
    frame_id: str = field(
        default="", metadata=param("wrench_stamped: the header's frame_id; '' = base_frame")
    )
    scale: float = field(
        default=1.0, metadata=param("driver command units per N (or N m)", "", 1e-9, 1e9)
    )
    delay_samples: int = field(
        default=-1,
        metadata=param(
            "driver cycles from a command's arrival to the cycle it acts in: 1 for ros2_control "
            "(written at its next update), 0 for a driver applying it on arrival; -1 = the "
            "profile's",
            "",
            -1,
            4,
        ),
    )


@dataclass(frozen=True)
class FrameSettings:
    """The driver's Cartesian axes against the model's base frame (``frame.*``)."""

    axes: list[int] | tuple[int, ...] = field(
        default_factory=lambda: [0, 1, 2],
        metadata=param(
            "force command and pose state: the driver's axis (0 x, 1 y, 2 z) of each model base "
            "axis",
            "",
            0,
            2,
        ),
    )
    signs: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [1.0, 1.0, 1.0],
        metadata=param(
            "+1 or -1 per model base axis: driver[axes[i]] = signs[i] * model[i]", "", -1.0, 1.0
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
