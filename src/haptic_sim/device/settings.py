"""The device node's parameters: the rows it declares and the settings its loop reads of them.

``device_node_specs`` is the whole table (``docs/parameters.md`` lists it in this order):
``safety_specs`` (the watchdog's timeout, the command guard's limits), the loop, input, command
authority (who may command the device), process, model, clock and simulation rows, then
``schedule_specs`` (lockstep re-sends, the start-up gate, recorder back-pressure, the statistics
file). ``DeviceLoopSettings`` is what the loop reads of them at run time (``missing_nodes``,
which of ``wait_for`` the graph lacks, is the nodes' common helper).
"""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from typing import Any

from haptic_dob.core.models.factory import model_specs
from haptic_dob.nodes.common import (
    CLOCK_MODES,
    command_authority_specs,
    input_specs,
    loop_specs,
    process_specs,
)
from haptic_dob.runtime.params import ParamSpec
from haptic_sim.device.factory import simulation_specs

DEFAULT_WAIT_FOR = ["environment_node", "observer_node", "controller_node"]


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
        *safety_specs(),
        *loop_specs(),
        *input_specs("reliable"),
        *command_authority_specs(),
        *process_specs(),
        # the slide's physics is plant.* (its truth), the point mass's cartesian.*; slide.* and
        # point_mass.* are the model the others assume
        *(s for s in model_specs() if s.name not in ASSUMED_ONLY),
        ParamSpec(
            "clock_mode",
            "lockstep",
            "lockstep: advance when command k arrived (stamps k * T); realtime: tick at rate_hz on "
            "the wall clock (stamps: the system clock when each sample is taken)",
            choices=CLOCK_MODES,
            read_only=True,
        ),
        *simulation_specs(),
        *schedule_specs(),
    ]


def safety_specs() -> list[ParamSpec]:
    """The realtime watchdog's timeout and the per-joint effort limits."""
    return [
        ParamSpec(
            "command_timeout_s",
            0.005,
            "realtime watchdog: zero effort when no valid command came for this long, counted in "
            "the samples the device sent (a stall of the device's own process does not count)",
            "s",
            0.0005,
            1.0,
        ),
        ParamSpec(
            "effort_limits",
            [0.0],
            "per-joint effort limit (N or N m) applied to every command, at most the actuator's "
            "saturation; [0.0] = the actuator's saturation",
        ),
    ]


def schedule_specs() -> list[ParamSpec]:
    """Lockstep re-sends, the start-up gate, recorder back-pressure and the statistics file."""
    return [
        ParamSpec(
            "lockstep_timeout_s",
            2.0,
            "lockstep: warn and re-send a sample after this long without its command (a "
            "best-effort input can drop a sample on a loaded machine)",
            "s",
            0.01,
            3600.0,
        ),
        ParamSpec(
            "wait_for",
            list(DEFAULT_WAIT_FOR),
            "nodes that must be up before sample 0, in both clock modes: a name in this "
            "namespace, or fully qualified (/rosbag2_recorder); realtime with []: tick at once, "
            "the watchdog holds zero effort until commands come",
            read_only=True,
        ),
        ParamSpec(
            "start_with",
            [],
            "devices this one starts its clock with, fully qualified (/slave/device_node): "
            "sample 0 waits until each has built its simulation (its joint_states publisher is "
            "up), so that the two sides of a teleoperation in real time tick from the same moment",
            read_only=True,
            items=str,
        ),
        ParamSpec(
            "start_delay_s",
            0.5,
            "settle time between the wait_for graph being up and "
            "sample 0 (endpoint matching between the other nodes)",
            "s",
            0.0,
            60.0,
            read_only=True,
        ),
        ParamSpec(
            "stats_file",
            "",
            "realtime: write cycle statistics (JSON) here at shutdown",
            read_only=True,
        ),
        ParamSpec(
            "max_recorder_lag_s",
            0.5,
            "lockstep: hold the loop while a recorder is this far behind in simulated time",
            "s",
            0.01,
            3600.0,
        ),
    ]


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
