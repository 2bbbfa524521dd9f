"""The loop's few message layouts in little-endian CDR, packed and read with ``struct``.

The 1 kHz path needs a stamp and three numbers from a ``WrenchStamped``, or a handful of joint
values: building and reading whole message objects (``rosbags``' generic codec, ``wire``) costs
an order of magnitude more than ``struct`` does. These functions cover what the
loop publishes and takes; each reader returns None for anything it does not know for sure
(big-endian data, a truncated message), and the caller then falls back on the generic codec.
Tests check byte equality with ``rosbags``' serializer.

CDR (XCDR1, as rmw_fastrtps writes it): a 4-byte encapsulation header (``00 01 00 00`` for
little endian), then the fields, each aligned to its own size counted from the end of that header;
a string is a uint32 length including its NUL, the characters and the NUL; a sequence is a uint32
count and its elements.
"""

from __future__ import annotations

import struct
from collections.abc import Sequence

LE = b"\x00\x01\x00\x00"  # CDR, little endian
NS_PER_S = 1_000_000_000

_U32 = struct.Struct("<I")
_STAMP = struct.Struct("<iII")  # sec, nanosec, frame_id length (with its NUL)


def _align(offset: int, n: int) -> int:
    """``offset`` (from the buffer's start) moved up to a multiple of ``n`` past the header."""
    return 4 + ((offset - 4 + n - 1) & ~(n - 1))


def _string(text: str) -> bytes:
    return text.encode() + b"\x00"


def header_struct(frame_id: str, tail: str) -> struct.Struct:
    """Encapsulation, ``std_msgs/Header`` (stamp, ``frame_id``) and ``tail`` (a ``struct``
    format, starting 8-aligned: doubles) as one ``Struct``: pack(LE, sec, nanosec, len, frame,
    *tail)."""
    frame = _string(frame_id)
    end = 16 + len(frame)
    pad = _align(end, 8) - end
    return struct.Struct(f"<4siII{len(frame)}s{pad}x{tail}")


class VectorLayout:
    """A stamped message whose payload is doubles (PoseStamped, TwistStamped, WrenchStamped): the
    first three are the vector the loop uses, ``rest`` are constant (orientation, torque...)."""

    def __init__(self, frame_id: str, rest: Sequence[float]) -> None:
        self._frame = _string(frame_id)
        self._rest = tuple(float(r) for r in rest)
        self._struct = header_struct(frame_id, f"{3 + len(self._rest)}d")

    def pack(self, stamp_ns: int, v: Sequence[float]) -> bytes:
        """The message of stamp ``stamp_ns`` carrying vector ``v``."""
        sec, nsec = divmod(stamp_ns, NS_PER_S)
        return self._struct.pack(LE, sec, nsec, len(self._frame), self._frame, *v, *self._rest)


_VEC3 = struct.Struct("<3d")


def read_vector(data: bytes | memoryview) -> tuple[int, tuple[float, float, float]] | None:
    """(stamp ns, first three doubles after the header) of a stamped geometry message."""
    if len(data) < 16 or data[1] != 1:
        return None
    sec, nsec, flen = _STAMP.unpack_from(data, 4)
    off = _align(16 + flen, 8)
    if off + 24 > len(data):
        return None
    return sec * NS_PER_S + nsec, _VEC3.unpack_from(data, off)


def _sequence_fmt(offset: int, n: int) -> tuple[str, int]:
    """Format of a sequence<double> of ``n`` at ``offset``, and the offset after it."""
    start = _align(offset, 4)
    fmt = f"{start - offset}xI"
    offset = start + 4
    if n:
        first = _align(offset, 8)
        fmt += f"{first - offset}x{n}d"
        offset = first + 8 * n
    return fmt, offset


class JointLayout:
    """``sensor_msgs/JointState`` for fixed joint names and value counts (one ``Struct``)."""

    def __init__(self, frame_id: str, names: Sequence[str], counts: Sequence[int]) -> None:
        frame = _string(frame_id)
        self._frame = frame
        offset = 16 + len(frame)
        start = _align(offset, 4)
        fmt = f"<4siII{len(frame)}s{start - offset}xI"
        offset = start + 4
        self._names: list[int | bytes] = []  # each name as (length with NUL, bytes)
        for name in names:
            text = _string(name)
            start = _align(offset, 4)
            fmt += f"{start - offset}xI{len(text)}s"
            offset = start + 4 + len(text)
            self._names += [len(text), text]
        self._n_names = len(names)
        for n in counts:
            part, offset = _sequence_fmt(offset, n)
            fmt += part
        self._struct = struct.Struct(fmt)
        self.counts = tuple(counts)

    def pack(
        self,
        stamp_ns: int,
        position: Sequence[float],
        velocity: Sequence[float],
        effort: Sequence[float],
    ) -> bytes:
        """The message of stamp ``stamp_ns`` (value counts as given at construction)."""
        sec, nsec = divmod(stamp_ns, NS_PER_S)
        return self._struct.pack(
            LE,
            sec,
            nsec,
            len(self._frame),
            self._frame,
            self._n_names,
            *self._names,
            len(position),
            *position,
            len(velocity),
            *velocity,
            len(effort),
            *effort,
        )


class JointReader:
    """Reads ``sensor_msgs/JointState``; a stream of messages with the same frame, names and
    value counts (a driver's, a device's) is read with one cached ``Struct`` after the first."""

    def __init__(self) -> None:
        self._key: bytes = b""
        self._names: tuple[str, ...] = ()
        self._values: struct.Struct | None = None
        self._counts: tuple[int, int, int] = (0, 0, 0)
        self._start = 0  # where the values start (0: nothing learnt yet)
        self._size = 0

    def __call__(
        self, data: bytes | memoryview
    ) -> (
        tuple[int, tuple[str, ...], tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None
    ):
        """(stamp ns, names, position, velocity, effort), or None (read it generically)."""
        if len(data) < 16 or data[1] != 1:
            return None
        start = self._start
        if start and len(data) == self._size and data[12:start] == self._key:
            sec, nsec = _STAMP2.unpack_from(data, 4)
            v = self._values.unpack_from(data, start)  # type: ignore[union-attr]  # set whenever _start is
            a, b, _ = self._counts
            return sec * NS_PER_S + nsec, self._names, v[:a], v[a : a + b], v[a + b :]
        return self._learn(data)

    def _learn(
        self, data: bytes | memoryview
    ) -> (
        tuple[int, tuple[str, ...], tuple[float, ...], tuple[float, ...], tuple[float, ...]] | None
    ):
        try:
            sec, nsec, flen = _STAMP.unpack_from(data, 4)
            off = _align(16 + flen, 4)
            (count,) = _U32.unpack_from(data, off)
            off += 4
            names = []
            for _ in range(count):
                off = _align(off, 4)
                (n,) = _U32.unpack_from(data, off)
                names.append(bytes(data[off + 4 : off + 3 + n]).decode())
                off += 4 + n
            names_end = off
            fmt, counts, values = "<", [], []
            for _ in range(3):
                start = _align(off, 4)
                (n,) = _U32.unpack_from(data, start)
                fmt += f"{start - off + 4}x"
                off = start + 4
                if n:
                    first = _align(off, 8)
                    fmt += f"{first - off}x{n}d"
                    values.append(struct.unpack_from(f"<{n}d", data, first))
                    off = first + 8 * n
                else:
                    values.append(())
                counts.append(n)
        except (struct.error, UnicodeDecodeError):
            return None
        if off != len(data):  # trailing bytes: not a layout to cache
            return sec * NS_PER_S + nsec, tuple(names), values[0], values[1], values[2]
        self._key = bytes(data[12:names_end])
        self._names = tuple(names)
        self._values = struct.Struct(fmt)
        self._counts = (counts[0], counts[1], counts[2])
        self._start = names_end
        self._size = len(data)
        return sec * NS_PER_S + nsec, self._names, values[0], values[1], values[2]


_STAMP2 = struct.Struct("<iI")


_ARRAY_STRUCTS: dict[tuple[int, int], struct.Struct] = {}


def pack_multi_array(label: str, data: Sequence[float]) -> bytes:
    """``std_msgs/Float64MultiArray`` with one dimension named ``label`` (size = stride = n)."""
    s = _string(label)
    n = len(data)
    layout = _ARRAY_STRUCTS.get((len(s), n))
    if layout is None:
        offset = 12 + len(s)  # after the dim count, the label's length and the label
        size_at = _align(offset, 4)
        head = f"<4sII{len(s)}s{size_at - offset}xIII"
        tail, _ = _sequence_fmt(struct.calcsize(head), n)
        layout = _ARRAY_STRUCTS[(len(s), n)] = struct.Struct(head + tail)
    return layout.pack(LE, 1, len(s), s, n, n, 0, n, *data)


def read_multi_array(data: bytes | memoryview) -> tuple[str | None, tuple[float, ...]] | None:
    """(first dimension's label or None, data) of a ``std_msgs/Float64MultiArray``."""
    try:
        if len(data) < 8 or data[1] != 1:
            return None
        (dims,) = _U32.unpack_from(data, 4)
        off = 8
        label = None
        for i in range(dims):
            off = _align(off, 4)
            (n,) = _U32.unpack_from(data, off)
            if i == 0:
                label = bytes(data[off + 4 : off + 3 + n]).decode()
            off = _align(off + 4 + n, 4) + 8  # size, stride
        off = _align(off, 4) + 4  # data_offset
        off = _align(off, 4)
        (n,) = _U32.unpack_from(data, off)
        off += 4
        if not n:
            return label, ()
        off = _align(off, 8)
        return label, struct.unpack_from(f"<{n}d", data, off)
    except (struct.error, UnicodeDecodeError):
        return None


_CLOCK = struct.Struct("<4siI")


def pack_clock(stamp_ns: int) -> bytes:
    """``rosgraph_msgs/Clock`` at ``stamp_ns``."""
    sec, nsec = divmod(stamp_ns, NS_PER_S)
    return _CLOCK.pack(LE, sec, nsec)
