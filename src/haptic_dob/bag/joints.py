"""One joint's position and effort out of a bag's ``sensor_msgs/JointState`` topic.

Any rosbag2 bag (MCAP or sqlite3, ours or ``ros2 bag record``'s): a bag holding nothing but
``/joint_states`` as a driver publishes it (name, position, velocity, effort) is enough for
``haptic-identify``. Stamps come from the messages' headers, or from the receive times when no
header is stamped (a driver that leaves them zero); a lockstep run's first sample is stamped 0
legitimately.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.bag.bagfile import listing, open_bag, resolve_topic, topics_of
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.series import JOINT_STATE
from haptic_dob.identification import JointRecord


def read_joint(
    path: str | Path, topic: str = "joint_states", joint: str | None = None
) -> JointRecord:
    """Stamps, positions and efforts of ``joint`` (None: the first) on ``topic`` of a bag."""
    from haptic_msgs_py.wire import TYPESTORE

    shown = str(path)
    with open_bag(path) as reader:
        topics = topics_of(reader)
        name = resolve_topic(topics, topic, "joint state", shown)
        if topics[name] != JOINT_STATE:
            raise BagError(f"{shown}: {name} is {topics[name]}, not {JOINT_STATE}")
        conns = [c for c in reader.connections if c.topic == name]
        stamps: list[int] = []
        received: list[int] = []
        pos: list[float] = []
        eff: list[float] = []
        j, chosen, last_names = 0, joint, None
        for _conn, t, data in reader.messages(connections=conns):
            msg: Any = TYPESTORE.deserialize_cdr(data, JOINT_STATE)
            names = list(msg.name)
            if names != last_names:  # a driver may change its joint list: look it up again
                j, last_names = _index(names, joint, shown, name), names
                chosen = names[j] if names else joint
            if len(msg.position) <= j:
                raise BagError(f"{shown}: {name} has no position for joint {chosen!r}")
            if len(msg.effort) <= j:
                raise BagError(
                    f"{shown}: {name} carries no effort for joint {chosen!r}; identification "
                    "needs the applied effort (the driver's effort field)"
                )
            st = msg.header.stamp
            stamps.append(st.sec * 1_000_000_000 + st.nanosec)
            received.append(t)
            pos.append(float(msg.position[j]))
            eff.append(float(msg.effort[j]))
    if not stamps:
        raise BagError(f"{shown}: {name} holds no messages; topics: {listing(topics)}")
    if not any(stamps):  # no header stamped: the receive times
        stamps = received
    order = np.argsort(np.asarray(stamps), kind="stable")
    return JointRecord(
        np.asarray(stamps, np.int64)[order],
        np.asarray(pos)[order],
        np.asarray(eff)[order],
        chosen or "joint 0",
    )


def _index(names: list[str], joint: str | None, shown: str, topic: str) -> int:
    if joint is None:
        return 0
    if joint not in names:
        raise BagError(f"{shown}: {topic} has no joint {joint!r}; joints: {', '.join(names)}")
    return names.index(joint)
