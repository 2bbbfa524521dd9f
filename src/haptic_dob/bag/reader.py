"""Read the series an analysis needs from a rosbag2 (MCAP or sqlite3) with ``rosbags``' AnyReader.

Only the chosen topics are read (motion, hand force, the velocity beside the motion, and
``/parameter_events``), streamed in batches: each message is reduced to its stamp and one number
(``haptic_dob.bag.cdr``), so an hour at 1 kHz needs tens of megabytes, not the whole topic.

Every problem with the file becomes a ``BagError`` naming the bag: missing path, not a bag,
truncated or corrupt, empty, a missing topic (with the topics there are) or one of the wrong type.
"""

from __future__ import annotations

import gc
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.bag.cdr import decode_joint, decode_vectors
from haptic_dob.bag.errors import BagError
from haptic_msgs_py.topics import EE_POSE, EE_TWIST, PARAMETER_EVENTS, WRENCH_MEASURED

POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"
TWIST = "geometry_msgs/msg/TwistStamped"
JOINT_STATE = "sensor_msgs/msg/JointState"
PARAMETER_EVENT = "rcl_interfaces/msg/ParameterEvent"
MOTION_TYPES = (POSE, JOINT_STATE)
AXES = {"x": 0, "y": 1, "z": 2}
BATCH = 16_384  # messages decoded at once per topic

_MCAP_MAGIC = b"\x89MCAP0\r\n"
_SQLITE_MAGIC = b"SQLite format 3\x00"


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
class Series:
    """One topic reduced to a number per message, sorted by stamp, repeated stamps dropped."""

    topic: str
    msgtype: str
    stamps_ns: np.ndarray  # int64 header stamps
    values: np.ndarray  # float64, one per stamp (the chosen coordinate)
    recv_ns: np.ndarray  # int64 bag (receive) time of each kept message
    duplicates: int = 0  # messages dropped because their stamp came again


@dataclass(frozen=True)
class ParamEvent:
    """One ``rcl_interfaces/msg/ParameterEvent`` as recorded."""

    time_ns: int  # bag (receive) time
    node: str  # fully qualified node name, e.g. /controller_node
    values: dict[str, Any]  # new and changed parameters
    deleted: tuple[str, ...]
    new: frozenset[str]  # the names in new_parameters (declarations, the recorder's snapshot)
    stamp_ns: int | None = None  # the event's own stamp (loop nodes: the sample it applies from)


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


# --- opening -------------------------------------------------------------------------------------
def check_bag_path(path: Path, shown: str) -> Path:
    """The path to open (bag directory or storage file); a ``BagError`` says what is wrong."""
    if not path.exists():
        raise BagError(f"{shown}: no such file or directory")
    if path.is_file() and path.name == "metadata.yaml":
        path = path.parent
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return path
        if any(path.glob("*.mcap")) or any(path.glob("*.db3")):
            raise BagError(
                f"{shown} is truncated or corrupt: the bag directory has no metadata.yaml "
                "(was the recording killed before it finished?)"
            )
        raise BagError(f"{shown} is not a bag: a directory without metadata.yaml")
    try:
        with path.open("rb") as fh:
            head = fh.read(16)
    except OSError as exc:
        raise BagError(f"{shown}: cannot read ({exc.strerror})") from None
    if not head:
        raise BagError(f"{shown} is not a bag: the file is empty")
    if not (head.startswith(_MCAP_MAGIC) or head.startswith(_SQLITE_MAGIC)):
        raise BagError(f"{shown} is not a bag (neither a rosbag2 directory, MCAP nor sqlite3)")
    if path.suffix not in (".mcap", ".db3"):
        kind = ".mcap" if head.startswith(_MCAP_MAGIC) else ".db3"
        raise BagError(f"{shown} looks like a {kind} storage file; name it *{kind} to read it")
    return path


def _corrupt(shown: str, exc: BaseException) -> BagError:
    detail = " ".join(str(exc).split()) or type(exc).__name__
    return BagError(f"{shown} is truncated or corrupt ({detail})")


@contextmanager
def open_bag(path: str | Path) -> Iterator[Any]:
    """An open ``rosbags.highlevel.AnyReader`` of one bag; problems become ``BagError``."""
    from rosbags.highlevel import AnyReader

    from haptic_msgs_py.wire import TYPESTORE

    shown = str(path)
    p = check_bag_path(Path(path), shown)
    reader = AnyReader([p], default_typestore=TYPESTORE)
    try:
        reader.open()
    except Exception as exc:  # rosbags raises several types for a damaged file
        raise _corrupt(shown, exc) from None
    try:
        yield reader
    finally:
        reader.close()


def topics_of(reader: Any) -> dict[str, str]:
    """Topic -> message type of an open reader."""
    return {c.topic: c.msgtype for c in reader.connections}


def listing(topics: dict[str, str]) -> str:
    """``/a (pkg/msg/A), /b (...)`` for error messages."""
    return ", ".join(f"{t} ({ty})" for t, ty in sorted(topics.items())) or "none"


def resolve_topic(topics: dict[str, str], name: str, what: str, shown: str) -> str:
    """The bag topic a (relative or absolute) name means; ``BagError`` if none or several."""
    if name.startswith("/"):
        found = [name] if name in topics else []
    else:
        found = ["/" + name] if "/" + name in topics else []
        if not found:
            found = sorted(t for t in topics if t.endswith("/" + name))
    if not found:
        raise BagError(f"{shown} has no {what} topic {name!r}; topics: {listing(topics)}")
    if len(found) > 1:
        raise BagError(
            f"{shown} has several {what} topics named {name!r} ({', '.join(found)}); "
            "give the full name"
        )
    return found[0]


# --- reading -------------------------------------------------------------------------------------
class _Accumulator:
    """Collects one topic's raw messages and reduces them to (stamp, value) batch by batch.

    The arrays are allocated once for the message count the bag's index gives, so no topic is
    ever held twice; receive times are kept only where asked (the motion topic).
    """

    def __init__(
        self, topic: str, msgtype: str, decode: Any, count: int, keep_recv: bool = False
    ) -> None:
        self.topic = topic
        self.msgtype = msgtype
        self.decode = decode  # list[bytes] -> (stamps (n,), values (n, k))
        self.datas: list[bytes] = []
        self.times: list[int] = []
        self.count = max(count, 1)
        self.n = 0
        self.stamps = np.empty(self.count, np.int64)
        self.recv = np.empty(self.count if keep_recv else 0, np.int64)
        self.keep_recv = keep_recv
        self.values: np.ndarray | None = None

    def _grow(self, need: int) -> None:
        size = max(need, 2 * self.count)
        self.stamps = np.resize(self.stamps, size)
        if self.keep_recv:
            self.recv = np.resize(self.recv, size)
        if self.values is not None:
            self.values = np.resize(self.values, (size, self.values.shape[1]))
        self.count = size

    def flush(self) -> None:
        if not self.datas:
            return
        stamps, values = self.decode(self.datas)
        a, b = self.n, self.n + stamps.size
        if b > self.count:  # more messages than the index said
            self._grow(b)
        if self.values is None:
            self.values = np.empty((self.count, values.shape[1]))
        self.stamps[a:b] = stamps
        self.values[a:b] = values
        if self.keep_recv:
            self.recv[a:b] = self.times
        self.n = b
        self.datas, self.times = [], []

    def series(self) -> Series:
        self.flush()
        n = self.n
        stamps = self.stamps[:n]
        values = self.values[:n] if self.values is not None else np.zeros((0, 1))
        recv = self.recv[:n] if self.keep_recv else self.recv
        if n > 1 and not bool(np.all(stamps[1:] >= stamps[:-1])):
            order = np.argsort(stamps, kind="stable")
            stamps, values = stamps[order], values[order]
            recv = recv[order] if self.keep_recv else recv
        dropped = 0
        if n > 1:
            repeat = stamps[1:] == stamps[:-1]
            dropped = int(repeat.sum())
            if dropped:
                keep = np.concatenate(([True], ~repeat))
                stamps, values = stamps[keep], values[keep]
                recv = recv[keep] if self.keep_recv else recv
        return Series(self.topic, self.msgtype, stamps, values, recv, dropped)


def _vector_decoder(msgtype: str, axis: int) -> Any:
    """Batch decoder: stamps and the ``axis`` component of a stamped vector message (n, 1)."""

    def decode(datas: list[bytes]) -> tuple[np.ndarray, np.ndarray]:
        return decode_vectors(datas, msgtype, (axis,))

    return decode


def _joint_decoder(joint: str | None, shown: str, topic: str) -> Any:
    """Batch decoder: stamps and (position, velocity) of one joint of JointState messages."""

    def decode(datas: list[bytes]) -> tuple[np.ndarray, np.ndarray]:
        try:
            stamps, pos, vel, _ = decode_joint(datas, joint)
        except KeyError as exc:
            names = _joint_names(datas[0])
            raise BagError(
                f"{shown}: {topic} has no joint {exc.args[0]!r} (joints: {', '.join(names)})"
            ) from None
        return stamps, np.column_stack((pos, vel))

    return decode


def _joint_names(data: bytes) -> list[str]:
    from haptic_msgs_py.wire import TYPESTORE

    msg: Any = TYPESTORE.deserialize_cdr(data, JOINT_STATE)
    return list(msg.name)


def _param_value(v: Any) -> Any:
    """Python value of a ``rcl_interfaces/msg/ParameterValue``."""
    t = int(v.type)
    if t == 1:
        return bool(v.bool_value)
    if t == 2:
        return int(v.integer_value)
    if t == 3:
        return float(v.double_value)
    if t == 4:
        return str(v.string_value)
    if t == 5:
        return [int(b) for b in v.byte_array_value]
    if t == 6:
        return [bool(b) for b in v.bool_array_value]
    if t == 7:
        return [int(i) for i in v.integer_array_value]
    if t == 8:
        return [float(d) for d in v.double_array_value]
    if t == 9:
        return [str(s) for s in v.string_array_value]
    return None


def param_event(msg: Any, time_ns: int) -> ParamEvent:
    """A ``ParamEvent`` of a decoded ParameterEvent message received at ``time_ns``."""
    values = {p.name: _param_value(p.value) for p in msg.new_parameters}
    values.update({p.name: _param_value(p.value) for p in msg.changed_parameters})
    deleted = tuple(p.name for p in msg.deleted_parameters)
    new = frozenset(p.name for p in msg.new_parameters)
    stamp = int(msg.stamp.sec) * 1_000_000_000 + int(msg.stamp.nanosec)
    return ParamEvent(time_ns, str(msg.node), values, deleted, new, stamp)


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
        accs: dict[str, _Accumulator] = {}
        twist = motion_topic.rsplit("/", 1)[0] + "/" + EE_TWIST
        if mtype == POSE:
            decode = _vector_decoder(mtype, axis)
        else:
            decode = _joint_decoder(sel.joint, shown, motion_topic)
        accs[motion_topic] = _Accumulator(
            motion_topic, mtype, decode, counts[motion_topic], keep_recv=True
        )
        if mtype == POSE and topics.get(twist) == TWIST and twist != force_topic:
            accs[twist] = _Accumulator(twist, TWIST, _vector_decoder(TWIST, axis), counts[twist])
        if force_topic in accs:
            raise BagError(f"{shown}: the motion and force topics are the same ({force_topic})")
        accs[force_topic] = _Accumulator(
            force_topic, ftype, _vector_decoder(ftype, axis), counts[force_topic]
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
            raise _corrupt(shown, exc) from None
        finally:
            if collecting:
                gc.enable()
    for topic in (motion_topic, force_topic):
        if series[topic].stamps_ns.size == 0:
            raise BagError(f"{shown}: topic {topic} has no messages")
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
        storage=_storage_of(check_bag_path(Path(path), shown)),
        topics=topics,
        message_count=count,
        motion=motion,
        force=force,
        velocity=velocity,
        events=events,
    )


def _storage_of(path: Path) -> str:
    if path.is_dir():
        return "mcap" if any(path.glob("*.mcap")) else "sqlite3"
    return "mcap" if path.suffix == ".mcap" else "sqlite3"


__all__ = [
    "AXES",
    "BagData",
    "ParamEvent",
    "Selection",
    "Series",
    "check_bag_path",
    "open_bag",
    "read_bag",
    "resolve_topic",
]
