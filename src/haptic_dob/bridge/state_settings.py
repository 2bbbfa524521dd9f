"""The driver's state topic as settings (``state.*``): type, QoS, joints, velocity, effort.

``StateSettings`` is one of ``DriverSettings``'s parameter groups (``driver_settings``);
``docs/devices.md`` says what each setting means for each driver.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from haptic_dob.runtime.params import param

STATE_TYPES = ("joint_states", "pose")
RELIABILITY = ("reliable", "best_effort")
VELOCITY_SOURCES = ("auto", "driver", "difference")
EFFORT_SOURCES = ("commanded", "driver")
STAMP_SOURCES = ("driver", "receipt")


@dataclass(frozen=True)
class StateSettings:
    """The driver's state topic (``state.*``) and how its values become the model's."""

    topic: str = field(
        default="",
        metadata=param(
            description=(
                "the driver's state topic (absolute, or relative to the bridge's namespace)"
            ),
            details=("Not the loop's own joint_states."),
        ),
    )
    type: str = field(
        default="joint_states",
        metadata=param(
            description=("sensor_msgs/JointState, or geometry_msgs/PoseStamped (Cartesian models)"),
            choices=STATE_TYPES,
            details=("A pose state suits a Cartesian model only: q is the tip's position."),
        ),
    )
    reliability: str = field(
        default="reliable",
        metadata=param(
            description="QoS reliability of the subscription",
            choices=RELIABILITY,
            details=(
                "reliable matches reliable publishers only (joint_state_broadcaster), best_effort "
                "matches both (SensorDataQoS drivers)."
            ),
        ),
    )
    depth: int = field(
        default=10, metadata=param(description="queue depth of the subscription", bounds=(1, 1000))
    )
    stamp: str = field(
        default="driver",
        metadata=param(
            description=("the stamp the loop's samples carry: the driver's, or the receipt time"),
            choices=STAMP_SOURCES,
            details=(
                "driver: the state's header stamp. receipt: the system clock when the state "
                "arrives, for a driver whose stamps are zero or do not advance."
            ),
        ),
    )
    joints: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            description="the driver's name of each model joint, in model order; [''] = the model's",
            details=("Other joints in the state (grippers, a gimbal) are ignored."),
        ),
    )
    signs: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [1.0],
        metadata=param(
            description=(
                "+1 or -1 per model joint (or one for all): model q = sign * scale * driver q"
            ),
            bounds=(-1.0, 1.0),
            details="Efforts and commands alike.",
        ),
    )
    scale: float = field(
        default=1.0,
        metadata=param(
            description="the driver's position unit in m or rad (0.001 for mm); velocities alike",
            bounds=(1e-9, 1e9),
        ),
    )
    velocity: str = field(
        default="auto",
        metadata=param(
            description=("joint velocity handed on: the driver's, a filtered difference, or auto"),
            choices=VELOCITY_SOURCES,
            details=(
                "driver: the driver's. difference: the backward difference of the positions, "
                "low-passed at velocity_cutoff_hz. auto: the driver's where its state has one."
            ),
        ),
    )
    velocity_cutoff_hz: float = field(
        default=100.0,
        metadata=param(
            description=(
                "cutoff of the first-order low-pass on the differenced velocity; 0 = unfiltered"
            ),
            unit="Hz",
            bounds=(0.0, 1e5),
        ),
    )
    encoder_resolution: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [0.0],
        metadata=param(
            description="each joint's position count (rad or m; one for all); 0 = low-pass",
            bounds=(0.0, 1.0),
            details=(
                "Set (> 0) for a differenced velocity by adaptive windowing: the slope of the "
                "least-squares line through the longest run of recent positions (at most "
                "velocity_window_samples periods) closer than half a count to it, in place of "
                "the low-pass. For coarse encoders (a Touch's joints: about 4e-4 rad). In the "
                "model's units (after scale); a joint published as the difference of two "
                "encoders' angles lies up to a whole count off: give it two."
            ),
        ),
    )
    velocity_window_samples: int = field(
        default=8,
        metadata=param(
            description="the adaptive window's longest span, in driver periods",
            bounds=(1, 64),
        ),
    )
    velocity_jerk_psd: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [0.0],
        metadata=param(
            description="each joint's white-jerk density (units^2/s^5); 0 = the adaptive window",
            bounds=(0.0, 1e12),
            details=(
                "One for all or one each; needs encoder_resolution. A steady-state Kalman filter "
                "per joint (constant acceleration, white jerk, the counts' rounding as noise) in "
                "place of the window: less lag at the same noise. Identify it from a session with "
                "the hand on the device: haptic-identify BAG --velocity-noise (docs/devices.md)."
            ),
        ),
    )
    effort: str = field(
        default="",
        metadata=param(
            description=("effort of [k-1, k) in the loop's joint_states; '' = the profile's"),
            choices=("", *EFFORT_SOURCES),
            details=("commanded: what the bridge commanded; driver: what the driver reports."),
        ),
    )
    timeout_s: float = field(
        default=0.01,
        metadata=param(
            description=(
                "watchdog: zero command when no driver state came for this long (wall clock)"
            ),
            unit="s",
            bounds=(0.001, 1.0),
            details="A stale state is not rendered.",
        ),
    )
