"""Joints' positions and efforts out of a bag's ``sensor_msgs/JointState`` topic.

Any rosbag2 bag (MCAP or sqlite3, ours or ``ros2 bag record``'s): a bag holding nothing but
``/joint_states`` as a driver publishes it (name, position, velocity, effort) is enough for
``haptic-identify``. Stamps come from the messages' headers, or from the bag (log) times when no
header is stamped (a driver that leaves them zero); a lockstep run's first sample is stamped 0
legitimately.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np
from numpy.typing import NDArray

from haptic_dob.bag.bagfile import listing, open_bag, resolve_topic, topics_of
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.series import JOINT_STATE
from haptic_dob.identification.one_dof import JointRecord
from haptic_msgs_py.wire import TYPESTORE


@dataclass(frozen=True)
class JointStates:
    """Several joints' samples: stamps (ns), positions (N, n) and efforts over [k-1, k) (N, n)."""

    stamps_ns: NDArray[np.int64]
    names: tuple[str, ...]
    position: NDArray[np.float64]
    effort: NDArray[np.float64]


def read_joints(
    path: str | Path,
    topic: str = "joint_states",
    joints: Sequence[str] | None = None,
    need_effort: bool = True,
) -> JointStates:
    """Stamps, positions and efforts of ``joints`` (None: every joint of the first message, in
    its order) on ``topic`` of a bag; ``BagError`` with one line when they are not there (the
    efforts NaN where a message has none and ``need_effort`` is False).

    Messages that do not name every wanted joint (a topic that interleaves an arm's and a
    gripper's states) are left out; a driver that names no joints gives its joints in order.
    """
    shown = str(path)
    chosen = bool(joints)
    with open_bag(path) as reader:
        topics = topics_of(reader)
        name = resolve_topic(topics, topic, "joint state", shown)
        if topics[name] != JOINT_STATE:
            raise BagError(f"{shown}: {name} is {topics[name]}, not {JOINT_STATE}")
        conns = [c for c in reader.connections if c.topic == name]
        stamps: list[int] = []
        received: list[int] = []
        pos: list[list[float]] = []
        eff: list[list[float]] = []
        wanted: list[str] = list(joints or ())
        idx: list[int] | None = None
        last_names: list[str] | None = None
        seen: dict[str, None] = {}  # every joint named, in the order first named
        for _conn, t, data in reader.messages(connections=conns):
            msg: Any = TYPESTORE.deserialize_cdr(data, JOINT_STATE)
            names = list(msg.name)
            if names != last_names:  # a driver may change its joint list: look them up again
                if not wanted:
                    wanted = names or [f"joint {i}" for i in range(len(msg.position))]
                idx, last_names = _indices(names, wanted, chosen, shown, name), names
                seen.update(dict.fromkeys(names))
            if idx is None:
                continue  # a message of other joints
            _check_fields(msg, idx, wanted, shown, name, need_effort)
            st = msg.header.stamp
            stamps.append(st.sec * 1_000_000_000 + st.nanosec)
            received.append(t)
            pos.append([float(msg.position[i]) for i in idx])
            eff.append([float(msg.effort[i]) if i < len(msg.effort) else np.nan for i in idx])
    if not stamps:
        if last_names is None:
            raise BagError(f"{shown}: {name} holds no messages; topics: {listing(topics)}")
        missing = [j for j in wanted if j not in seen]
        if missing:
            why = f"has no joint {missing[0]!r}"
        else:
            why = f"names {', '.join(wanted)} in no one message"
        raise BagError(f"{shown}: {name} {why}; joints: {', '.join(seen)}")
    if not any(stamps):  # no header stamped: the bag (log) times
        stamps = received
    order = np.argsort(np.asarray(stamps), kind="stable")
    return JointStates(
        np.asarray(stamps, np.int64)[order],
        tuple(wanted),
        np.asarray(pos, np.float64)[order],
        np.asarray(eff, np.float64)[order],
    )


def read_joint(
    path: str | Path, topic: str = "joint_states", joint: str | None = None
) -> JointRecord:
    """Stamps, positions and efforts of ``joint`` (None: the first) on ``topic`` of a bag."""
    js = read_joints(path, topic, [joint] if joint else None)
    return JointRecord(js.stamps_ns, js.position[:, 0], js.effort[:, 0], js.names[0])


def _indices(
    names: list[str], wanted: list[str], chosen: bool, shown: str, topic: str
) -> list[int] | None:
    """Where the wanted joints are in a message naming ``names``; None when it lacks one."""
    if not names:
        if chosen:
            raise BagError(f"{shown}: {topic} names no joints, so it has no joint {wanted[0]!r}")
        return list(range(len(wanted)))
    if any(j not in names for j in wanted):
        return None
    return [names.index(j) for j in wanted]


def _check_fields(
    msg: Any, idx: list[int], wanted: list[str], shown: str, topic: str, need_effort: bool
) -> None:
    """A position (and an effort, if needed) for every wanted joint, or one line naming the
    first missing."""
    for i, joint in zip(idx, wanted, strict=True):
        if len(msg.position) <= i:
            raise BagError(f"{shown}: {topic} has no position for joint {joint!r}")
        if need_effort and len(msg.effort) <= i:
            raise BagError(
                f"{shown}: {topic} carries no effort for joint {joint!r}; identification "
                "needs the applied effort (the driver's effort field)"
            )
