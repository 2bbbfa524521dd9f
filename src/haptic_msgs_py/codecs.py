"""Loop values to CDR bytes and back: the loop's layouts packed directly, anything else generic.

One ``Codec`` per message type: ``encoder(frame_id)`` returns a function value -> bytes (a
publisher calls it for readers in other processes, after the command), ``decode`` turns received
bytes into the value the nodes take. The loop's own messages go through ``haptic_msgs_py.cdr``
(``struct``, a fraction of a microsecond); what that does not recognise (big-endian CDR, say) is
decoded by the ``rosbags`` message classes of ``wire``. The bytes are the CDR any ROS 2 tool reads
and writes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from haptic_msgs_py import cdr, wire
from haptic_msgs_py.stamps import NS_PER_S, command_label, command_parts
from haptic_msgs_py.values import EffortCommand, JointSample, Stamp, StampedVector

Encoder = Callable[[Any], bytes]
Decoder = Callable[[bytes | memoryview], Any]


@dataclass(frozen=True)
class Codec:
    """How one message type becomes a loop value and back."""

    typename: str
    make_encoder: Callable[[str], Encoder]
    make_decoder: Callable[[], Decoder]

    def encoder(self, frame_id: str = "") -> Encoder:
        """A function value -> CDR bytes; messages carry ``frame_id`` (headerless types: none)."""
        return self.make_encoder(frame_id)

    def decoder(self) -> Decoder:
        """A function CDR bytes -> value, for one stream (it may cache the stream's layout)."""
        return self.make_decoder()

    def decode(self, data: bytes | memoryview) -> Any:
        """One message's value (a fresh decoder: for tools and tests, not for a stream)."""
        return self.make_decoder()(data)


def _vector_codec(typename: str, path: tuple[str, str], rest: tuple[float, ...]) -> Codec:
    outer, inner = path
    deserialize = wire.decoder(typename)
    read = cdr.read_vector

    def make_encoder(frame_id: str) -> Encoder:
        pack = cdr.VectorLayout(frame_id, rest).pack

        def encode(value: StampedVector) -> bytes:
            return pack(value.stamp_ns, value.vector)

        return encode

    def decode(data: bytes | memoryview) -> StampedVector:
        fast = read(data)
        if fast is not None:
            return StampedVector(*fast)
        m = deserialize(data)
        st = m.header.stamp
        v = getattr(getattr(m, outer), inner)
        return StampedVector(st.sec * NS_PER_S + st.nanosec, (v.x, v.y, v.z))

    return Codec(typename, make_encoder, lambda: decode)


#: orientation identity; angular velocity and torque zero
POSE = _vector_codec("geometry_msgs/msg/PoseStamped", ("pose", "position"), (0.0, 0.0, 0.0, 1.0))
TWIST = _vector_codec("geometry_msgs/msg/TwistStamped", ("twist", "linear"), (0.0, 0.0, 0.0))
WRENCH = _vector_codec("geometry_msgs/msg/WrenchStamped", ("wrench", "force"), (0.0, 0.0, 0.0))


def _floats(values: Any) -> tuple[float, ...]:
    return tuple(values.tolist()) if isinstance(values, np.ndarray) else tuple(map(float, values))


def _joint_encoder(frame_id: str) -> Encoder:
    layouts: dict[tuple[tuple[str, ...], int, int, int], cdr.JointLayout] = {}

    def encode(value: JointSample) -> bytes:
        key = (value.name, len(value.position), len(value.velocity), len(value.effort))
        layout = layouts.get(key)
        if layout is None:
            layout = layouts[key] = cdr.JointLayout(frame_id, key[0], key[1:])
        return layout.pack(value.stamp_ns, value.position, value.velocity, value.effort)

    return encode


_decode_joint_state = wire.decoder("sensor_msgs/msg/JointState")


def _joint_decoder() -> Callable[[bytes | memoryview], JointSample]:
    """A decoder with its own layout cache (one per subscription: one stream of messages)."""
    read = cdr.JointReader()

    def decode(data: bytes | memoryview) -> JointSample:
        fast = read(data)
        if fast is not None:
            return JointSample(*fast)
        return _joint_decode_generic(data)

    return decode


def _joint_decode_generic(data: bytes | memoryview) -> JointSample:
    m = _decode_joint_state(data)
    st = m.header.stamp
    return JointSample(
        st.sec * NS_PER_S + st.nanosec,
        tuple(m.name),
        _floats(m.position),
        _floats(m.velocity),
        _floats(m.effort),
    )


JOINT_STATE = Codec("sensor_msgs/msg/JointState", _joint_encoder, _joint_decoder)


def _command_encoder(_frame_id: str) -> Encoder:
    def encode(value: EffortCommand) -> bytes:
        label = "" if value.stamp_ns is None else command_label(value.stamp_ns, value.token)
        return cdr.pack_multi_array(label, value.effort)

    return encode


_decode_multi_array = wire.decoder("std_msgs/msg/Float64MultiArray")


def _command_decode(data: bytes | memoryview) -> EffortCommand:
    fast = cdr.read_multi_array(data)
    if fast is not None:
        label, values = fast
    else:
        m = _decode_multi_array(data)
        label, values = (m.layout.dim[0].label if m.layout.dim else None), _floats(m.data)
    if label is None:
        return EffortCommand(None, values)
    stamp, token = command_parts(label)
    return EffortCommand(stamp, values, token)


#: ``std_msgs/Float64MultiArray`` in joint order, the cycle (and the sender's token) named in the
#: first label
EFFORT = Codec("std_msgs/msg/Float64MultiArray", _command_encoder, lambda: _command_decode)


def _clock_encoder(_frame_id: str) -> Encoder:
    def encode(value: Stamp) -> bytes:
        return cdr.pack_clock(value.stamp_ns)

    return encode


_decode_clock = wire.decoder("rosgraph_msgs/msg/Clock")


def _clock_decode(data: bytes | memoryview) -> Stamp:
    st = _decode_clock(data).clock
    return Stamp(st.sec * NS_PER_S + st.nanosec)


CLOCK = Codec("rosgraph_msgs/msg/Clock", _clock_encoder, lambda: _clock_decode)

#: the codec of each session topic (``topics.SESSION_TOPICS``) and of ``/clock``
TOPIC_CODECS: dict[str, Codec] = {
    "joint_states": JOINT_STATE,
    "ee_pose": POSE,
    "ee_twist": TWIST,
    "wrench_measured": WRENCH,
    "sim/hand_wrench": WRENCH,
    "wrench_desired": WRENCH,
    "wrench_estimate": WRENCH,
    "effort_estimate": JOINT_STATE,
    "effort_command": EFFORT,
    "/clock": CLOCK,
}
