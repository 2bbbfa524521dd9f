"""Parameter groups of the loop nodes, as frozen settings dataclasses (``runtime.params``).

Shared by every loop node: ``LoopTiming`` (rate and frame, the same on every node of a session),
``LoopInputs`` (its inputs' QoS), ``ProcessSettings`` (CPUs). A device end (the simulated device,
the bridge) takes ``CommandInputSettings`` (who may command it), a controller
``CommandOutputSettings`` (the token its commands carry). ``ControllerSettings`` and
``ChannelEnd`` are the controller's and the channel's own rows.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from haptic_dob.core.command_join import FALLBACKS
from haptic_dob.runtime.params import param
from haptic_msgs_py.topics import DEFAULT_BASE_FRAME, INPUT_RELIABILITY

ROLES = ("master", "slave")  # the ends of a teleoperation channel


@dataclass(frozen=True)
class LoopTiming:
    """``rate_hz`` and the base frame: the same on every node of a session (YAML ``/**``)."""

    rate_hz: float = field(
        default=1000.0,
        metadata=param(
            description="control rate of the loop", unit="Hz", bounds=(1.0, 1e5), read_only=True
        ),
    )
    base_frame: str = field(
        default=DEFAULT_BASE_FRAME,
        metadata=param(description="frame of poses, twists and wrenches", read_only=True),
    )


@dataclass(frozen=True)
class LoopInputs:
    """How a node subscribes to its loop inputs: ``best_effort`` for sensor streams; a device
    end's command input overrides it with ``reliable`` (``specs_of(..., defaults=...)``)."""

    input_reliability: str = field(
        default="best_effort",
        metadata=param(
            description="QoS reliability of this node's loop inputs",
            choices=INPUT_RELIABILITY,
            read_only=True,
            details=(
                "reliable: a one-off message (ros2 topic pub --once) is asked for again and "
                "arrives while its publisher lives; the default of a device's effort_command. "
                "best_effort: no acknowledgements, the default of the sensor streams; nodes in "
                "separate processes cycle faster (BENCHMARKS.md), and a message sent before the "
                "reader matched its writer can be lost. Nodes sharing a process hand values over "
                "in process either way."
            ),
        ),
    )


#: a device end's default: a command is not sensor data (``specs_of(LoopInputs, defaults=...)``)
RELIABLE_INPUTS = {"input_reliability": "reliable"}


@dataclass(frozen=True)
class CommandInputSettings:
    """Who may command a device end (the simulated device node, the device bridge): the command
    source, the session's token, the bench switch (``haptic_dob.core.command_authority``)."""

    command_source: str = field(
        default="controller_node",
        metadata=param(
            description=("the node whose effort_command moves the device from another process"),
            read_only=True,
            details=(
                "A name in this namespace, or fully qualified. Commands handed over in this "
                "process (the loop composed) always do."
            ),
        ),
    )
    command_token: str = field(
        default="",
        metadata=param(
            description=(
                "this session's command token; '' = the one command_source's commands carry"
            ),
            read_only=True,
            details=(
                "A command from another process moves the device only when its layout label "
                "carries it (effort@<stamp>#<token>); haptic-launch writes a fresh one for a "
                "device and its controller at every launch. '' = the token of command_source's "
                "commands, taken while the graph shows that node (name and GID) as the only "
                "publisher. Not a secret from anyone on the network (docs/safety.md)."
            ),
        ),
    )
    open_command_input: bool = field(
        default=False,
        metadata=param(
            description=(
                "take effort_command from any publisher (bench work); false: command_source's"
            ),
            read_only=True,
            details=(
                "Bench work: ros2 topic pub, a tool of your own. False: only command_source's "
                "commands move the device; the others are refused, counted in /diagnostics and "
                "named once each in the log. At start-up only: no one on the network can open it "
                "with ros2 param set."
            ),
        ),
    )


@dataclass(frozen=True)
class CommandOutputSettings:
    """The token a command source's ``effort_command`` carries (the controllers)."""

    command_token: str = field(
        default="",
        metadata=param(
            description=(
                "the token this node's effort_command carries; '' = a new one at every start"
            ),
            read_only=True,
            details=(
                "Carried in the command's layout label (effort@<stamp>#<token>), by which the "
                "device takes commands from another process; haptic-launch writes the session's."
            ),
        ),
    )


@dataclass(frozen=True)
class ProcessSettings:
    """Per-process settings of a loop node (``cpu_affinity``, ``cpu_latency_us``)."""

    cpu_affinity: list[int] | tuple[int, ...] = field(
        default_factory=list,
        metadata=param(
            description=("CPUs this node's process runs on, every thread; [] = not pinned"),
            read_only=True,
            details=(
                "As ros2_control's cpu_affinity; [] = wherever the system schedules it. "
                "haptic-launch --pin fills it per node."
            ),
        ),
    )
    cpu_latency_us: int = field(
        default=-1,
        metadata=param(
            description=(
                "CPU idle states' largest exit latency while it runs (PM QoS); -1 = no request"
            ),
            unit="us",
            bounds=(-1, 1_000_000),
            read_only=True,
            details=(
                "A Linux PM QoS request on /dev/cpu_dma_latency, held open while the process runs; "
                "it needs write access to it (root as a rule), and a node that cannot make it does "
                "not start. 0 = idle CPUs poll and wake at once (costs power; on a virtual machine "
                "only 0 helps). haptic-launch --cpu-latency sets it on every loop node."
            ),
        ),
    )


@dataclass(frozen=True)
class ControllerSettings:
    """The controller node's own rows beside its law (``ImpedanceLaw``)."""

    input_warn_s: float = field(
        default=2.0,
        metadata=param(
            description="warn when an input of a pending cycle is this late",
            unit="s",
            bounds=(0.01, 3600.0),
        ),
    )
    warm_inputs: bool = field(
        default=True,
        metadata=param(
            description=("subscribe to every mode's force input (false: the start mode's only)"),
            read_only=True,
            details=(
                "So a switch to CL or DOB finds its input flowing. False is cheaper, but a switch "
                "to another mode is then refused."
            ),
        ),
    )
    fallback: str = field(
        default="zero",
        metadata=param(
            description="what to render when the mode's force input stops: zero force or OL",
            choices=FALLBACKS,
        ),
    )
    input_timeout_s: float = field(
        default=0.02,
        metadata=param(
            description=("sample time after which the mode's force input counts as stopped"),
            unit="s",
            bounds=(0.001, 10.0),
            details=(
                "The input counts as stopped when its newest sample is this much sample time older "
                "than the cycle."
            ),
        ),
    )


@dataclass(frozen=True)
class ChannelEnd:
    """Which end of the teleoperation channel a channel node is, and how it waits for its peer."""

    role: str = field(
        default="master",
        metadata=param(description="which end of the channel", choices=ROLES, read_only=True),
    )
    wait_for_peer: bool = field(
        default=True,
        metadata=param(
            description="lockstep: sample k waits for the peer's messages that can be due by k",
            read_only=True,
        ),
    )
