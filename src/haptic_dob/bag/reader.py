"""Read the series an analysis needs from a rosbag2 (MCAP or sqlite3) with ``rosbags``' AnyReader.

Only the chosen topics are read (motion, hand force, the velocity beside the motion, and
``/parameter_events``), streamed in batches into ``Series`` (``haptic_dob.bag.series``).

Every problem with the file becomes a ``BagError`` naming the bag (``haptic_dob.bag.bagfile``):
missing path, not a bag, truncated or corrupt, empty, a missing topic (with the topics there are)
or one of the wrong type.
"""

from __future__ import annotations

import gc
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from haptic_dob.bag.bagfile import (
    check_bag_path,
    corrupt,
    listing,
    open_bag,
    resolve_topic,
    storage_of,
    topics_of,
)
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.param_events import PARAMETER_EVENT, ParamEvent, param_event
from haptic_dob.bag.series import (
    JOINT_STATE,
    POSE,
    TWIST,
    WRENCH,
    Accumulator,
    Series,
    joint_decoder,
    vector_decoder,
)
from haptic_msgs_py.topics import EE_POSE, EE_TWIST, PARAMETER_EVENTS, WRENCH_MEASURED

MOTION_TYPES = (POSE, JOINT_STATE)
AXES = {"x": 0, "y": 1, "z": 2}
BATCH = 16_384  # messages decoded at once per topic
#: what an empty wrench_measured means: a device without a force sensor (a bridge's)
NO_SENSOR = (
    " (the device has no force sensor: --force-topic wrench_estimate analyses the observer's "
    "estimate of a DOB session instead)"
)


@dataclass(frozen=True)
class Selection:
    """Which topics and which coordinate to read (topic names relative or absolute)."""

    motion_topic: str = EE_POSE
    force_topic: str = WRENCH_MEASURED
    axis: str = "x"
    joint: str | None = None

    def __post_init__(self) -> None:
        if self.axis not in AXES:
            raise ValueError(f"axis must be one of x, y, z, got {self.axis!r}")


@dataclass
class BagData:
    """What ``read_bag`` returns: the motion, force and velocity series and parameter events."""

    path: str
    storage: str
    topics: dict[str, str]  # every topic of the bag -> type
    message_count: int
    motion: Series
    force: Series
    velocity: Series | None  # None: differentiate the motion
    events: list[ParamEvent] = field(default_factory=list)

    @property
    def namespace(self) -> str:
        """Namespace of the motion topic ('' or '/ns'): whose node parameters label segments."""
        return self.motion.topic.rsplit("/", 1)[0]


def read_bag(path: str | Path, selection: Selection | None = None) -> BagData:
    """Stream the motion, force and velocity series and the parameter events out of a bag."""
    sel = selection or Selection()
    shown = str(path)
    axis = AXES[sel.axis]
    with open_bag(path) as reader:
        topics = topics_of(reader)
        count = reader.message_count
        if count == 0:
            raise BagError(f"{shown} is an empty bag (no messages; topics: {listing(topics)})")
        motion_topic = resolve_topic(topics, sel.motion_topic, "motion", shown)
        force_topic = resolve_topic(topics, sel.force_topic, "force", shown)
        mtype, ftype = topics[motion_topic], topics[force_topic]
        if mtype not in MOTION_TYPES:
            raise BagError(
                f"{shown}: the motion topic {motion_topic} is {mtype}; it must be "
                f"{POSE} or {JOINT_STATE}"
            )
        if ftype != WRENCH:
            raise BagError(
                f"{shown}: the force topic {force_topic} is {ftype}; it must be {WRENCH}"
            )
        counts: dict[str, int] = {}
        for c in reader.connections:
            counts[c.topic] = counts.get(c.topic, 0) + c.msgcount
        accs: dict[str, Accumulator] = {}
        twist = motion_topic.rsplit("/", 1)[0] + "/" + EE_TWIST
        if mtype == POSE:
            decode = vector_decoder(mtype, axis)
        else:
            decode = joint_decoder(sel.joint, shown, motion_topic)
        accs[motion_topic] = Accumulator(
            motion_topic, mtype, decode, counts[motion_topic], keep_recv=True
        )
        if mtype == POSE and topics.get(twist) == TWIST and twist != force_topic:
            accs[twist] = Accumulator(twist, TWIST, vector_decoder(TWIST, axis), counts[twist])
        if force_topic in accs:
            raise BagError(f"{shown}: the motion and force topics are the same ({force_topic})")
        accs[force_topic] = Accumulator(
            force_topic, ftype, vector_decoder(ftype, axis), counts[force_topic]
        )
        conns = [c for c in reader.connections if c.topic in accs or c.topic == PARAMETER_EVENTS]
        by_id = {c.id: accs.get(c.topic) for c in conns}
        events: list[ParamEvent] = []
        collecting = gc.isenabled()
        gc.disable()  # millions of short-lived messages: the cyclic collector only costs time
        try:
            for conn, t, data in reader.messages(connections=conns):
                acc = by_id[conn.id]
                if acc is None:
                    if conn.msgtype == PARAMETER_EVENT:
                        events.append(param_event(reader.deserialize(data, conn.msgtype), t))
                    continue
                acc.datas.append(data)
                acc.times.append(t)
                if len(acc.datas) >= BATCH:
                    acc.flush()
            series = {topic: acc.series() for topic, acc in accs.items()}
        except BagError:
            raise
        except Exception as exc:  # a damaged chunk or record
            raise corrupt(shown, exc) from None
        finally:
            if collecting:
                gc.enable()
    for topic in (motion_topic, force_topic):
        if series[topic].stamps_ns.size == 0:
            why = NO_SENSOR if topic == force_topic and topic.endswith(WRENCH_MEASURED) else ""
            raise BagError(f"{shown}: topic {topic} has no messages{why}")
    motion = series[motion_topic]
    velocity = None
    if mtype == POSE:
        if twist in series and series[twist].stamps_ns.size:
            velocity = series[twist]
    elif np.all(np.isfinite(motion.values[:, 1])):
        velocity = Series(
            motion.topic, mtype, motion.stamps_ns, motion.values[:, 1].copy(), motion.recv_ns
        )
    motion.values = motion.values[:, 0] if mtype == POSE else motion.values[:, 0].copy()
    force = series[force_topic]
    force.values = force.values[:, 0]
    if velocity is not None and velocity.values.ndim == 2:
        velocity.values = velocity.values[:, 0]
    events.sort(key=lambda e: e.time_ns)
    return BagData(
        path=shown,
        storage=storage_of(check_bag_path(Path(path), shown)),
        topics=topics,
        message_count=count,
        motion=motion,
        force=force,
        velocity=velocity,
        events=events,
    )


__all__ = [
    "AXES",
    "BagData",
    "Selection",
    "open_bag",
    "read_bag",
]
