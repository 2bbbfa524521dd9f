"""Fast readers of the few CDR fields the analysis needs, straight from the serialized bytes.

A recorded hour at 1 kHz holds millions of messages; decoding each into a message object costs
a few microseconds. The stamped geometry messages (``PoseStamped``, ``WrenchStamped``,
``TwistStamped``) have a fixed layout once the header's ``frame_id`` is known: little-endian CDR,
a 4-byte encapsulation header, ``stamp.sec`` (int32) at byte 4, ``stamp.nanosec`` (uint32) at 8,
the ``frame_id`` length (uint32, with its NUL) at 12, its characters from 16, then float64 fields
aligned to 8 bytes (alignment counted from byte 4). A batch of messages of equal length and
equal ``frame_id`` length is read with one numpy structured view; anything else (big-endian
CDR, mixed lengths) goes through the ``rosbags`` deserializer, which is exact but slower.
"""

from __future__ import annotations

import struct
from collections.abc import Callable, Mapping, Sequence
from typing import Any

import numpy as np

from haptic_msgs_py.stamps import COMMAND_LABEL, NS_PER_S, TOKEN_MARK
from haptic_msgs_py.topics import EFFORT_COMMAND
from haptic_msgs_py.wire import TYPESTORE

StampReader = Callable[[bytes], int | None]

#: stamped geometry types: the message's 3-vector field read as components 0..2 after the header
VECTOR_FIELD: dict[str, tuple[str, str]] = {
    "geometry_msgs/msg/PoseStamped": ("pose", "position"),
    "geometry_msgs/msg/WrenchStamped": ("wrench", "force"),
    "geometry_msgs/msg/TwistStamped": ("twist", "linear"),
}

_STAMP = struct.Struct("<iI")  # sec, nanosec (at byte 4)
_U32 = struct.Struct("<I")


def _first_double(frame_len: int) -> int:
    """Byte offset of the first float64 after a header whose frame_id has ``frame_len`` bytes."""
    end = 16 + frame_len
    return 4 + ((end - 4 + 7) & ~7)


def header_stamp_ns(data: bytes | memoryview) -> int | None:
    """``header.stamp`` (ns) of any little-endian CDR message that starts with a Header."""
    if len(data) < 12 or data[1] != 1:
        return None
    sec, nsec = _STAMP.unpack_from(data, 4)
    return int(sec * NS_PER_S + nsec)


def command_label_stamp_ns(data: bytes | memoryview) -> int | None:
    """The stamp named by a little-endian ``Float64MultiArray``'s first label (``effort@<ns>``,
    a sender's ``#<token>`` after it)."""
    if len(data) < 12 or data[1] != 1 or _U32.unpack_from(data, 4)[0] < 1:
        return None
    n = _U32.unpack_from(data, 8)[0]
    label = bytes(data[12 : 12 + max(n - 1, 0)])
    if not label.startswith(COMMAND_LABEL.encode()):
        return None
    try:
        return int(label[len(COMMAND_LABEL) :].partition(TOKEN_MARK.encode())[0])
    except ValueError:
        return None


def stamp_reader(
    topic: str, typename: str, fielddefs: Mapping[str, Any] = TYPESTORE.fielddefs
) -> StampReader | None:
    """How to read the stamp (ns) of a message of ``topic`` from its bytes: its header's, or an
    ``effort_command``'s label; None when it carries none. ``fielddefs``: a rosbags typestore's
    (one that knows ``typename``)."""
    fields = fielddefs[typename][1]
    if fields and fields[0][0] == "header":
        return header_stamp_ns
    if topic.rsplit("/", 1)[-1] == EFFORT_COMMAND:
        return command_label_stamp_ns
    return None


def decode_vectors(
    datas: Sequence[bytes], typename: str, components: Sequence[int]
) -> tuple[np.ndarray, np.ndarray]:
    """Stamps (int64 ns) and the chosen components of the vector field of stamped messages.

    Args:
        datas: serialized messages of one stamped geometry type (see ``VECTOR_FIELD``).
        typename: their type.
        components: indices 0..2 (x, y, z) of the vector field to return.

    Returns:
        (stamps_ns of shape (n,), values of shape (n, len(components)), float64).
    """
    n = len(datas)
    cols = list(components)
    if n == 0:
        return np.zeros(0, np.int64), np.zeros((0, len(cols)))
    size = len(datas[0])
    lens = np.fromiter(map(len, datas), np.int64, n)
    if size >= 16 and datas[0][1] == 1 and bool(np.all(lens == size)):
        buf = b"".join(datas)
        head = np.frombuffer(
            buf,
            np.dtype(
                {
                    "names": ["enc", "sec", "nsec", "flen"],
                    "formats": ["u1", "<i4", "<u4", "<u4"],
                    "offsets": [1, 4, 8, 12],
                    "itemsize": size,
                }
            ),
        )
        flen = int(head["flen"][0])
        first = _first_double(flen)
        if (
            first + 24 <= size
            and bool(np.all(head["enc"] == 1))
            and bool(np.all(head["flen"] == flen))
        ):
            body = np.frombuffer(
                buf,
                np.dtype(
                    {
                        "names": [f"c{c}" for c in cols],
                        "formats": ["<f8"] * len(cols),
                        "offsets": [first + 8 * c for c in cols],
                        "itemsize": size,
                    }
                ),
            )
            stamps = head["sec"].astype(np.int64) * NS_PER_S + head["nsec"].astype(np.int64)
            values = np.empty((n, len(cols)))
            for j, c in enumerate(cols):
                values[:, j] = body[f"c{c}"]
            return stamps, values
    return _decode_vectors_slow(datas, typename, cols)


def _decode_vectors_slow(
    datas: Sequence[bytes], typename: str, cols: list[int]
) -> tuple[np.ndarray, np.ndarray]:
    """The exact path: rosbags' deserializer, message by message."""
    outer, inner = VECTOR_FIELD[typename]
    names = "xyz"
    stamps = np.empty(len(datas), np.int64)
    values = np.empty((len(datas), len(cols)))
    for i, data in enumerate(datas):
        msg: Any = TYPESTORE.deserialize_cdr(data, typename)
        st = msg.header.stamp
        stamps[i] = st.sec * NS_PER_S + st.nanosec
        vec = getattr(getattr(msg, outer), inner)
        for j, c in enumerate(cols):
            values[i, j] = getattr(vec, names[c])
    return stamps, values


def decode_joint(
    datas: Sequence[bytes], joint: str | None
) -> tuple[np.ndarray, np.ndarray, np.ndarray, list[str]]:
    """Stamps, position and velocity (nan where absent) of one joint of ``JointState`` messages.

    ``joint`` None takes the first joint. Returns (stamps_ns, position, velocity, names of the
    first message); raises ``KeyError`` naming the joint when a message lacks it.
    """
    n = len(datas)
    stamps = np.empty(n, np.int64)
    pos = np.empty(n)
    vel = np.empty(n)
    names: list[str] = []
    for i, data in enumerate(datas):
        msg: Any = TYPESTORE.deserialize_cdr(data, "sensor_msgs/msg/JointState")
        if i == 0:
            names = list(msg.name)
        st = msg.header.stamp
        stamps[i] = st.sec * NS_PER_S + st.nanosec
        if joint is None:
            j = 0
        else:
            try:
                j = list(msg.name).index(joint)
            except ValueError:
                raise KeyError(joint) from None
        if len(msg.position) <= j:
            raise KeyError(joint if joint is not None else "<first joint>")
        pos[i] = msg.position[j]
        vel[i] = msg.velocity[j] if len(msg.velocity) > j else np.nan
    return stamps, pos, vel, names
