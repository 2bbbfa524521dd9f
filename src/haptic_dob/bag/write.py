"""Write session bags from arrays with ``rosbags`` (tests, benchmarks, exporting batch runs).

The bag looks like a recording of the node graph: ``ee_pose``, ``ee_twist`` and
``wrench_measured`` per sample (optionally every other session topic too), stamps ``k * T``,
receive (bag) times ``epoch + k * T``, and ``/parameter_events`` with one snapshot per node
before the first sample plus a change event just before the sample where it takes effect.
Messages are encoded once as templates and then patched in place (stamp and numbers), so an
hour at 1 kHz is written at the speed of the storage writer. ``open_writer`` opens a new bag for
any writer (the recorder's too).
"""

from __future__ import annotations

import os
import struct
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from rosbags.rosbag2 import StoragePlugin, Writer

from haptic_dob.bag.jazzy import JazzyWriter
from haptic_msgs_py import wire
from haptic_msgs_py.stamps import NS_PER_S, period_ns
from haptic_msgs_py.topics import (
    EE_POSE,
    EE_TWIST,
    EFFORT_COMMAND,
    EFFORT_ESTIMATE,
    HAND_WRENCH,
    JOINT_STATES,
    PARAMETER_EVENTS,
    SESSION_TOPICS,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)

EPOCH_NS = 1_767_225_600 * NS_PER_S  # 2026-01-01: receive times of written bags start here
_MARK = 1.0e-300  # marker values located in a template's bytes
_STAMP = struct.Struct("<iI")
_D = struct.Struct("<d")


class Template:
    """A message encoded once; ``fill`` patches its stamp and numbers into a fresh copy."""

    def __init__(self, msg: Any, count: int, stamped: bool = True) -> None:
        self.data = wire.encode(msg)
        self.stamped = stamped
        self.offsets = []
        for i in range(count):
            pos = self.data.find(_D.pack(_MARK * (i + 1)))
            if pos < 0:
                raise ValueError(f"marker {i} not found in the template of {msg.__msgtype__}")
            self.offsets.append(pos)
        self._pack = struct.Struct("<" + "d" * count) if self._contiguous() else None

    def _contiguous(self) -> bool:
        return all(b - a == 8 for a, b in zip(self.offsets, self.offsets[1:], strict=False))

    def fill(self, stamp_ns: int, values: Sequence[float]) -> bytes:
        """The template with ``header.stamp`` = ``stamp_ns`` and the marked numbers set."""
        buf = bytearray(self.data)
        if self.stamped:
            _STAMP.pack_into(buf, 4, *divmod(stamp_ns, NS_PER_S))
        if self._pack is not None:
            self._pack.pack_into(buf, self.offsets[0], *values)
        else:
            for off, v in zip(self.offsets, values, strict=True):
                _D.pack_into(buf, off, v)
        return bytes(buf)


def _marks(n: int) -> list[float]:
    return [_MARK * (i + 1) for i in range(n)]


def vector_template(typename: str, frame: str = "base_link") -> Template:
    """PoseStamped / TwistStamped / WrenchStamped template: its first 3-vector is patched."""
    m = _marks(3)
    if typename == SESSION_TOPICS[EE_POSE]:
        msg = wire.pose_stamped(frame)
        p = msg.pose.position
    elif typename == SESSION_TOPICS[EE_TWIST]:
        msg = wire.twist_stamped(frame)
        p = msg.twist.linear
    else:
        msg = wire.wrench_stamped(frame)
        p = msg.wrench.force
    p.x, p.y, p.z = m
    return Template(msg, 3)


def joint_template(name: str = "slide", frame: str = "base_link") -> Template:
    """JointState of one joint: position, velocity, effort patched."""
    msg = wire.joint_state([name], frame)
    m = _marks(3)
    msg.position, msg.velocity, msg.effort = (np.array([v]) for v in m)
    return Template(msg, 3)


class CommandTemplate:
    """Float64MultiArray effort command of one joint labelled ``effort@<stamp>`` (stamp padded
    to 19 digits so every message has the same layout; ``command_stamp`` reads it as usual)."""

    def __init__(self) -> None:
        self.template = Template(
            wire.float64_multi_array("effort@" + "0" * 19, _marks(1)), 1, stamped=False
        )
        self.label_at = self.template.data.find(b"effort@") + 7

    def fill(self, stamp_ns: int, value: float) -> bytes:
        """The command of the cycle stamped ``stamp_ns`` with effort ``value``."""
        buf = bytearray(self.template.data)
        buf[self.label_at : self.label_at + 19] = b"%019d" % stamp_ns
        _D.pack_into(buf, self.template.offsets[0], value)
        return bytes(buf)


#: ``rcl_interfaces/msg/ParameterValue`` type codes -> the field holding the value
VALUE_FIELDS = {
    1: "bool_value",
    2: "integer_value",
    3: "double_value",
    4: "string_value",
    5: "byte_array_value",
    6: "bool_array_value",
    7: "integer_array_value",
    8: "double_array_value",
    9: "string_array_value",
}
_ARRAY_DTYPES = {5: np.uint8, 6: bool, 7: np.int64, 8: np.float64}


def value_type(value: Any) -> int:
    """The ParameterValue type code of a Python value (lists of numbers are doubles)."""
    if isinstance(value, bool):
        return 1
    if isinstance(value, int):
        return 2
    if isinstance(value, float):
        return 3
    if isinstance(value, str):
        return 4
    if isinstance(value, (list, tuple)):
        if value and all(isinstance(v, str) for v in value):
            return 9
        if value and all(isinstance(v, bool) for v in value):
            return 6
        return 8
    raise ValueError(f"cannot write parameter value {value!r}")


def parameter_value(value: Any, kind: int | None = None) -> Any:
    """A rosbags ``rcl_interfaces/msg/ParameterValue`` holding ``value`` (type code ``kind``,
    default from the Python type; 0 = not set)."""
    kind = value_type(value) if kind is None else int(kind)
    kw: dict[str, Any] = {
        "type": kind,
        "bool_value": False,
        "integer_value": 0,
        "double_value": 0.0,
        "string_value": "",
        "byte_array_value": np.zeros(0, np.uint8),
        "bool_array_value": np.zeros(0, bool),
        "integer_array_value": np.zeros(0, np.int64),
        "double_array_value": np.zeros(0),
        "string_array_value": [],
    }
    if kind in _ARRAY_DTYPES:
        items = [v[0] if isinstance(v, bytes) else v for v in value]
        kw[VALUE_FIELDS[kind]] = np.asarray(items, _ARRAY_DTYPES[kind])
    elif kind == 9:
        kw["string_array_value"] = [str(v) for v in value]
    elif kind in VALUE_FIELDS:
        kw[VALUE_FIELDS[kind]] = value
    return wire.TYPESTORE.types["rcl_interfaces/msg/ParameterValue"](**kw)


def parameter_event(
    node: str,
    values: Mapping[str, Any],
    stamp_ns: int,
    snapshot: bool,
    kinds: Mapping[str, int] | None = None,
) -> bytes:
    """CDR bytes of a ParameterEvent: ``values`` as new (snapshot) or changed parameters.

    ``kinds`` gives type codes where the Python type is ambiguous (an integer array).
    """
    types = wire.TYPESTORE.types
    kinds = kinds or {}
    params = [
        types["rcl_interfaces/msg/Parameter"](name=k, value=parameter_value(v, kinds.get(k)))
        for k, v in values.items()
    ]
    sec, nsec = divmod(stamp_ns, NS_PER_S)
    ev = types["rcl_interfaces/msg/ParameterEvent"](
        stamp=wire.Time(sec=sec, nanosec=nsec),
        node=node,
        new_parameters=params if snapshot else [],
        changed_parameters=[] if snapshot else params,
        deleted_parameters=[],
    )
    return wire.encode(ev)


def open_writer(path: str | Path, storage: str) -> Writer:
    """An open ``rosbags`` writer of a new bag (rosbag2 format 9, as Jazzy writes it:
    ``haptic_dob.bag.jazzy``) in ``storage`` (mcap, sqlite3).

    Raises ``rosbags.rosbag2.WriterError`` or ``OSError`` when the bag cannot be created.
    """
    plugin = {"mcap": StoragePlugin.MCAP, "sqlite3": StoragePlugin.SQLITE3}[storage]
    writer = JazzyWriter(Path(path), version=9, storage_plugin=plugin)
    writer.open()
    return writer


def make_durable(writer: Writer) -> None:
    """Put everything written so far into complete records on disk, so that a recording killed
    later (kill -9, a crash, a power cut) keeps it: MCAP closes its pending chunk and flushes and
    syncs the file, sqlite3 commits. ``haptic-record --recover`` reads such a bag back.

    Uses the storage writer that ``rosbags`` keeps open (``writer.storage``): rosbags offers no
    public call for it.
    """
    storage = writer.storage
    close_chunk = getattr(storage, "close_chunk", None)
    if close_chunk is not None:  # MCAP
        if storage.chunk.bio.tell():  # type: ignore[union-attr]  # the MCAP writer has chunk
            close_chunk()
        bio = storage.bio  # type: ignore[union-attr]  # the MCAP writer has bio
        bio.flush()
        os.fsync(bio.fileno())
    conn = getattr(storage, "conn", None)
    if conn is not None:  # sqlite3
        conn.commit()


@dataclass(frozen=True)
class ParamChange:
    """Parameters of one node that change just before sample ``index``."""

    index: int
    node: str
    values: dict[str, Any]


def write_session_bag(
    path: str | Path,
    x: np.ndarray,
    force: np.ndarray,
    rate_hz: float,
    params: Mapping[str, Mapping[str, Any]],
    changes: Sequence[ParamChange] = (),
    velocity: np.ndarray | None = None,
    storage: str = "mcap",
    all_topics: bool = False,
    namespace: str = "",
) -> int:
    """Write a bag of a 1-D session along x; returns the number of messages written.

    Args:
        x, force, velocity: per-sample position (m), hand force (N), velocity (m/s).
        rate_hz: sample rate; sample k has stamp ``k / rate_hz``.
        params: node name -> parameters at the start (one snapshot event per node).
        changes: parameter changes, each received just before its sample.
        all_topics: also write joint_states, sim/hand_wrench, wrench_desired,
            wrench_estimate, effort_estimate and effort_command (what a recording holds).
        namespace: '' or '/ns' for topic and node names.
    """
    n = int(np.asarray(x).size)
    xs = np.asarray(x, np.float64).tolist()
    fs_ = np.asarray(force, np.float64).tolist()
    vs = None if velocity is None else np.asarray(velocity, np.float64).tolist()
    period = period_ns(rate_hz)
    ns = namespace.rstrip("/")
    writer = open_writer(path, storage)
    count = 0
    try:

        def conn(topic: str, typename: str) -> Any:
            name = topic if topic.startswith("/") else f"{ns}/{topic}"
            return writer.add_connection(name, typename, typestore=wire.TYPESTORE)

        c_pose = conn(EE_POSE, SESSION_TOPICS[EE_POSE])
        c_force = conn(WRENCH_MEASURED, SESSION_TOPICS[WRENCH_MEASURED])
        c_twist = conn(EE_TWIST, SESSION_TOPICS[EE_TWIST]) if vs is not None else None
        c_params = conn(PARAMETER_EVENTS, "rcl_interfaces/msg/ParameterEvent")
        t_pose = vector_template(SESSION_TOPICS[EE_POSE])
        t_wrench = vector_template(SESSION_TOPICS[WRENCH_MEASURED])
        t_twist = vector_template(SESSION_TOPICS[EE_TWIST])
        extra: list[tuple[Any, Template, str]] = []
        if all_topics:
            for topic in (HAND_WRENCH, WRENCH_DESIRED, WRENCH_ESTIMATE):
                extra.append((conn(topic, SESSION_TOPICS[topic]), t_wrench, "f"))
            extra.append((conn(JOINT_STATES, SESSION_TOPICS[JOINT_STATES]), joint_template(), "js"))
            extra.append(
                (conn(EFFORT_ESTIMATE, SESSION_TOPICS[EFFORT_ESTIMATE]), joint_template(), "js")
            )
        c_cmd = conn(EFFORT_COMMAND, SESSION_TOPICS[EFFORT_COMMAND]) if all_topics else None
        t_cmd = CommandTemplate()
        write = writer.write
        for node, values in params.items():
            write(
                c_params,
                EPOCH_NS - period,
                parameter_event(f"{ns}/{node}", values, EPOCH_NS - period, True),
            )
            count += 1
        pending = sorted(changes, key=lambda c: c.index)
        j = 0
        for k in range(n):
            stamp = k * period
            t = EPOCH_NS + stamp
            while j < len(pending) and pending[j].index <= k:
                ch = pending[j]
                write(c_params, t - 1, parameter_event(f"{ns}/{ch.node}", ch.values, t - 1, False))
                count += 1
                j += 1
            xk, fk = xs[k], fs_[k]
            write(c_pose, t, t_pose.fill(stamp, (xk, 0.0, 0.0)))
            write(c_force, t, t_wrench.fill(stamp, (fk, 0.0, 0.0)))
            count += 2
            if c_twist is not None:
                write(c_twist, t, t_twist.fill(stamp, (vs[k], 0.0, 0.0)))  # type: ignore[index]  # vs is set whenever c_twist is
                count += 1
            for c, tpl, kind in extra:
                if kind == "f":
                    write(c, t, tpl.fill(stamp, (-fk, 0.0, 0.0)))
                else:
                    write(c, t, tpl.fill(stamp, (xk, 0.0 if vs is None else vs[k], fk)))
                count += 1
            if c_cmd is not None:
                write(c_cmd, t, t_cmd.fill(stamp, fk))
                count += 1
    except BaseException:
        writer.close()
        raise
    writer.close()
    return count
