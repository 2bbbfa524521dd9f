"""One topic of a bag reduced to a number per message: ``Series`` and its batch accumulator.

Each message is reduced to its header stamp and the chosen coordinate(s) (``haptic_dob.bag.cdr``)
batch by batch, into arrays allocated once for the message count the bag's index gives, so an
hour at 1 kHz needs tens of megabytes, not the whole topic.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from haptic_dob.bag.cdr import decode_joint, decode_vectors
from haptic_dob.bag.errors import BagError
from haptic_msgs_py.wire import TYPESTORE

POSE = "geometry_msgs/msg/PoseStamped"
WRENCH = "geometry_msgs/msg/WrenchStamped"
TWIST = "geometry_msgs/msg/TwistStamped"
JOINT_STATE = "sensor_msgs/msg/JointState"

#: list of serialized messages -> (stamps (n,) int64 ns, values (n, k) float64)
Decoder = Callable[[list[bytes]], tuple[np.ndarray, np.ndarray]]


@dataclass
class Series:
    """One topic reduced to a number per message, sorted by stamp, repeated stamps dropped."""

    topic: str
    msgtype: str
    stamps_ns: np.ndarray  # int64 header stamps
    values: np.ndarray  # float64, one per stamp (the chosen coordinate)
    recv_ns: np.ndarray  # int64 bag (log) time of each kept message
    duplicates: int = 0  # messages dropped because their stamp came again


class Accumulator:
    """Collects one topic's raw messages and reduces them to (stamp, value) batch by batch.

    The arrays are allocated once for the message count the bag's index gives, so no topic is
    ever held twice; receive times are kept only where asked (the motion topic).
    """

    def __init__(
        self, topic: str, msgtype: str, decode: Decoder, count: int, keep_recv: bool = False
    ) -> None:
        self.topic = topic
        self.msgtype = msgtype
        self.decode = decode
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
        """Decode the messages collected since the last flush into the arrays."""
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
        """Everything collected, sorted by stamp, repeated stamps dropped (values (n, k))."""
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


def vector_decoder(msgtype: str, axis: int) -> Decoder:
    """Batch decoder: stamps and the ``axis`` component of a stamped vector message (n, 1)."""

    def decode(datas: list[bytes]) -> tuple[np.ndarray, np.ndarray]:
        return decode_vectors(datas, msgtype, (axis,))

    return decode


def joint_decoder(joint: str | None, shown: str, topic: str) -> Decoder:
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
    msg: Any = TYPESTORE.deserialize_cdr(data, JOINT_STATE)
    return list(msg.name)
