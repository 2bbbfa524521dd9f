"""The recorder's parameters, and the name of the bag it creates (never over an existing one).

Light to import (no bag or ROS modules): ``haptic-record`` checks its arguments with it first.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from haptic_dob.runtime.params import ParamSpec, param, specs_of
from haptic_msgs_py.topics import PARAMETER_EVENTS, RECORDER_PROGRESS, SESSION_TOPICS

STORAGES = ("mcap", "sqlite3")  # bag storages (``haptic_dob.bag.write.open_writer``)
LOG_TIMES = ("session", "receive")  # a message's bag time (``haptic_dob.recorder.recording``)
DEFAULT_TOPICS = [*SESSION_TOPICS, PARAMETER_EVENTS]  # every session topic and the events


@dataclass(frozen=True)
class RecorderSettings:
    """The recorder node's parameters (all but ``rate_hz`` fixed at start)."""

    output: str = field(
        default="",
        metadata=param(
            description=(
                "bag directory to create ('' = haptic_<date>_<time> in the working directory)"
            ),
            read_only=True,
        ),
    )
    storage: str = field(
        default="mcap",
        metadata=param(description="bag storage", choices=STORAGES, read_only=True),
    )
    log_time: str = field(
        default="session",
        metadata=param(
            description=("bag time of each message: the session's time, or the receive time"),
            choices=LOG_TIMES,
            read_only=True,
            details=(
                "session: the session's time (a loop message's own stamp, anything else the newest "
                "stamp or /clock received; as ros2 bag record --use-sim-time). receive: the "
                "wall-clock receive time (as ros2 bag record)."
            ),
        ),
    )
    topics: list[str] | tuple[str, ...] = field(
        default_factory=lambda: list(DEFAULT_TOPICS),
        metadata=param(
            description=("topics to record: session topics by name, others as NAME:pkg/msg/Type"),
            read_only=True,
            details=(
                "Session topics and /parameter_events by name, any other topic as "
                "NAME:pkg/msg/Type."
            ),
        ),
    )
    namespaces: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            description=(
                "namespaces whose nodes it snapshots and devices it reports to; [''] = its own"
            ),
            read_only=True,
            details=(
                "It reports its progress on <ns>/recorder/progress. A teleoperation graph: "
                "[/master, /slave]."
            ),
        ),
    )
    duration_s: float = field(
        default=0.0,
        metadata=param(
            description="stop after this long (wall clock); 0 = until stopped",
            unit="s",
            bounds=(0.0, 1e7),
            read_only=True,
        ),
    )
    rate_hz: float = field(
        default=1000.0,
        metadata=param(
            description="sample rate of the loop (to count missing stamps)",
            unit="Hz",
            bounds=(1.0, 1e5),
        ),
    )
    progress_rate_hz: float = field(
        default=50.0,
        metadata=param(
            description="rate of recorder/progress (lockstep back-pressure)",
            unit="Hz",
            bounds=(20.0, 1000.0),
            read_only=True,
        ),
    )
    snapshot_timeout_s: float = field(
        default=2.0,
        metadata=param(
            description=(
                "warn when a node has not answered the parameter snapshot after this long"
            ),
            unit="s",
            bounds=(0.1, 60.0),
            read_only=True,
            details=(
                "The node is still asked, the question sent again every this long (a response may "
                "be lost)."
            ),
        ),
    )
    drain_timeout_s: float = field(
        default=2.0,
        metadata=param(
            description="at shutdown: take queued messages for at most this long",
            unit="s",
            bounds=(0.0, 60.0),
            read_only=True,
        ),
    )


def recorder_specs() -> list[ParamSpec]:
    """Every parameter of the recorder node."""
    return specs_of(RecorderSettings)


def new_bag_path(output: str) -> Path:
    """The bag directory to create: ``output``, or ``haptic_<date>_<time>`` when it is empty;
    ``ValueError`` when it exists (the recorder never overwrites a bag)."""
    path = Path(output or time.strftime("haptic_%Y%m%d_%H%M%S"))
    if path.exists():
        raise ValueError(f"{path} exists already; the recorder never overwrites a bag")
    return path


def progress_topic(namespace: str) -> str:
    """Where the devices of ``namespace`` ('' = the recorder's own) read its progress."""
    return f"{namespace.rstrip('/')}/{RECORDER_PROGRESS}" if namespace else RECORDER_PROGRESS
