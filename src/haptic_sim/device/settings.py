"""The device node's parameters: the rows it declares and the settings its loop reads of them.

``device_node_specs`` is the whole table (``docs/parameters.md`` lists it in this order):
``DeviceSafety`` (the watchdog's timeout, the command guard's limits), the loop, input, command
authority (who may command the device), process, model, clock and simulation rows, then
``DeviceSchedule`` (lockstep re-sends, the start-up gate, recorder back-pressure, the statistics
file). ``DeviceLoopSettings`` is what the loop reads of them at run time (``missing_nodes``,
which of ``wait_for`` the graph lacks, is the nodes' common helper).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from typing import Any

from haptic_dob.core.models.factory import model_specs
from haptic_dob.nodes.settings import (
    RELIABLE_INPUTS,
    CommandInputSettings,
    LoopInputs,
    LoopTiming,
    ProcessSettings,
)
from haptic_dob.runtime.params import ParamSpec, param, specs_of
from haptic_sim.device.factory import simulation_specs

DEFAULT_WAIT_FOR = ["environment_node", "observer_node", "controller_node"]
CLOCK_MODES = ("lockstep", "realtime")


#: model parameters a simulated device does not take (its own physics are ``plant.*`` or
#: ``cartesian.*``)
ASSUMED_ONLY = frozenset(
    {
        "slide.mass_kg",
        "slide.viscous_n_s_per_m",
        "slide.coulomb_n",
        "point_mass.mass_kg",
        "point_mass.viscous_n_s_per_m",
        "point_mass.coulomb_n",
    }
)


def device_node_specs() -> list[ParamSpec]:
    """Every parameter of the device node."""
    return [
        *specs_of(DeviceSafety),
        *specs_of(LoopTiming),
        *specs_of(LoopInputs, defaults=RELIABLE_INPUTS),
        *specs_of(CommandInputSettings),
        *specs_of(ProcessSettings),
        # the slide's physics is plant.* (its truth), the point mass's cartesian.*; slide.* and
        # point_mass.* are the model the others assume
        *(s for s in model_specs() if s.name not in ASSUMED_ONLY),
        *specs_of(DeviceClock),
        *simulation_specs(),
        *specs_of(DeviceSchedule),
    ]


@dataclass(frozen=True)
class DeviceSafety:
    """The realtime watchdog's timeout and the per-joint effort limits."""

    command_timeout_s: float = field(
        default=0.005,
        metadata=param(
            description=("realtime watchdog: zero effort after this long without a valid command"),
            unit="s",
            bounds=(0.0005, 1.0),
            details=(
                "Counted in the samples the device sent: a stall of the device's own process does "
                "not count."
            ),
        ),
    )
    effort_limits: list[float] | tuple[float, ...] = field(
        default_factory=lambda: [0.0],
        metadata=param(
            description="per-joint effort limit (N or N m) on every command; [0.0] = saturation",
            details=("At most the actuator's saturation; [0.0] = the actuator's saturation."),
        ),
    )


@dataclass(frozen=True)
class DeviceClock:
    """Whether the device steps in lockstep or ticks in real time."""

    clock_mode: str = field(
        default="lockstep",
        metadata=param(
            description=("lockstep: step when command k arrived; realtime: tick on the wall clock"),
            choices=CLOCK_MODES,
            read_only=True,
            details=(
                "lockstep: sample k is stamped k * T. realtime: ticks at rate_hz on the wall "
                "clock, each sample stamped with the system clock when it is taken."
            ),
        ),
    )


@dataclass(frozen=True)
class DeviceSchedule:
    """Lockstep re-sends, the start-up gate, recorder back-pressure and the statistics file."""

    lockstep_timeout_s: float = field(
        default=2.0,
        metadata=param(
            description=("lockstep: warn and re-send a sample after this long without its command"),
            unit="s",
            bounds=(0.01, 3600.0),
            details="A best-effort input can drop a sample on a loaded machine.",
        ),
    )
    wait_for: list[str] | tuple[str, ...] = field(
        default_factory=lambda: list(DEFAULT_WAIT_FOR),
        metadata=param(
            description="nodes that must be up before sample 0, in either clock mode",
            read_only=True,
            details=(
                "A name in this namespace, or fully qualified (/rosbag2_recorder). realtime with "
                "[]: tick at once, the watchdog holding zero effort until commands come."
            ),
        ),
    )
    start_with: list[str] | tuple[str, ...] = field(
        default_factory=list,
        metadata=param(
            description=(
                "devices this one starts its clock with, fully qualified (/slave/device_node)"
            ),
            read_only=True,
            details=(
                "Sample 0 waits until each has built its simulation (its joint_states publisher is "
                "up), so that the two sides of a teleoperation in real time tick from the same "
                "moment."
            ),
        ),
    )
    start_delay_s: float = field(
        default=0.5,
        metadata=param(
            description="settle time between the wait_for graph being up and sample 0",
            unit="s",
            bounds=(0.0, 60.0),
            read_only=True,
            details="For the endpoint matching between the other nodes.",
        ),
    )
    stats_file: str = field(
        default="",
        metadata=param(
            description="realtime: write cycle statistics (JSON) here at shutdown", read_only=True
        ),
    )
    max_recorder_lag_s: float = field(
        default=0.5,
        metadata=param(
            description=(
                "lockstep: hold the loop while a recorder is this far behind in simulated time"
            ),
            unit="s",
            bounds=(0.01, 3600.0),
        ),
    )


@dataclass(frozen=True)
class DeviceLoopSettings:
    """What the loop reads of its parameters at run time (a new snapshot on every change)."""

    effort_limits: tuple[float, ...]  # per joint, N or N m (checked against the actuator)
    command_timeout_s: float  # realtime watchdog, s of simulated time
    lockstep_timeout_s: float  # re-send a sample after this long without its command, s
    max_recorder_lag_s: float  # hold the loop while a recorder is this far behind, s
    start_delay_s: float  # settle time between the graph being up and sample 0, s
    wait_for: tuple[str, ...]  # nodes that must be up before sample 0

    @classmethod
    def of(cls, values: Mapping[str, Any], effort_limits: tuple[float, ...]) -> DeviceLoopSettings:
        """The settings in a node's parameter values, with the limits ``effort_limits`` gave."""
        return cls(
            effort_limits,
            values["command_timeout_s"],
            values["lockstep_timeout_s"],
            values["max_recorder_lag_s"],
            values["start_delay_s"],
            tuple(values["wait_for"]),
        )


def start_topics(start_with: Iterable[str]) -> list[str]:
    """The ``joint_states`` topic of each ``start_with`` device (its node's namespace); a name
    that is not fully qualified raises ``ValueError``."""
    out = []
    for name in start_with:
        if not name.startswith("/") or name.endswith("/"):
            raise ValueError(
                f"start_with names devices fully qualified (/ns/device_node): {name!r}"
            )
        out.append(f"{name.rpartition('/')[0]}/joint_states")
    return out
