"""Loop values on the wire: the packed layouts are byte for byte what rosbags serializes, and
every reader falls back on the generic codec for what it does not know."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic_msgs_py import cdr, codecs, wire
from haptic_msgs_py.stamps import command_label, command_parts, command_stamp
from haptic_msgs_py.values import EffortCommand, JointSample, Stamp, StampedVector

frames = st.sampled_from(["", "a", "base_link", "abcdefgh", "ee_link_of_a_long_arm"])
stamps = st.integers(min_value=0, max_value=2**31 * 10**9 - 1)
floats = st.floats(allow_nan=False, allow_infinity=False, width=64)
names = st.lists(st.text(alphabet="abcdefghij_0123", min_size=1, max_size=12), max_size=7)


def _set_stamp(msg, stamp_ns: int) -> None:
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp_ns, 10**9)


@given(frame=frames, stamp=stamps, v=st.tuples(floats, floats, floats))
@settings(max_examples=60, deadline=None)
def test_stamped_vectors_encode_as_rosbags_does_and_decode_back(frame, stamp, v) -> None:
    for codec, make, field in (
        (codecs.POSE, wire.pose_stamped, ("pose", "position")),
        (codecs.TWIST, wire.twist_stamped, ("twist", "linear")),
        (codecs.WRENCH, wire.wrench_stamped, ("wrench", "force")),
    ):
        msg = make(frame)
        _set_stamp(msg, stamp)
        vec = getattr(getattr(msg, field[0]), field[1])
        vec.x, vec.y, vec.z = v
        data = codec.encoder(frame)(StampedVector(stamp, v))
        assert data == wire.encode(msg)
        assert codec.decode(data) == StampedVector(stamp, v)


@given(frame=frames, stamp=stamps, joint_names=names, data=st.data())
@settings(max_examples=60, deadline=None)
def test_joint_states_encode_as_rosbags_does_and_decode_back(frame, stamp, joint_names, data):
    n = len(joint_names)
    values = [tuple(data.draw(st.lists(floats, min_size=c, max_size=c))) for c in (n, n, 0)]
    msg = wire.joint_state(joint_names, frame)
    _set_stamp(msg, stamp)
    msg.position, msg.velocity, msg.effort = (np.array(x, dtype=np.float64) for x in values)
    value = JointSample(stamp, tuple(joint_names), *values)
    encoded = codecs.JOINT_STATE.encoder(frame)(value)
    assert encoded == wire.encode(msg)
    decode = codecs.JOINT_STATE.decoder()
    assert decode(encoded) == value
    assert decode(encoded) == value  # the second time from the layout it learnt


@given(stamp=st.one_of(st.none(), stamps), effort=st.lists(floats, max_size=7))
@settings(max_examples=60, deadline=None)
def test_effort_commands_encode_as_rosbags_does_and_decode_back(stamp, effort) -> None:
    label = "" if stamp is None else command_label(stamp)
    msg = wire.float64_multi_array(label, effort)
    value = EffortCommand(stamp, tuple(effort))
    encoded = codecs.EFFORT.encoder()(value)
    assert encoded == wire.encode(msg)
    assert codecs.EFFORT.decode(encoded) == value


tokens = st.text(alphabet="0123456789abcdef#", max_size=16)


@given(stamp=stamps, token=tokens, effort=st.lists(floats, max_size=7))
@settings(max_examples=60, deadline=None)
def test_an_effort_command_carries_its_senders_token_after_the_stamp(stamp, token, effort) -> None:
    value = EffortCommand(stamp, tuple(effort), token)
    encoded = codecs.EFFORT.encoder()(value)
    assert encoded == wire.encode(wire.float64_multi_array(command_label(stamp, token), effort))
    assert codecs.EFFORT.decode(encoded) == value
    assert command_parts(command_label(stamp, token)) == (stamp, token)


@pytest.mark.parametrize(
    ("label", "parts"),
    [
        ("effort@5", (5, "")),
        ("effort@5#tok", (5, "tok")),
        ("effort@#tok", (None, "tok")),  # a token without a stamp: the newest command
        ("effort@x#tok", (None, "tok")),
        ("effort", (None, "")),
        ("", (None, "")),
        ("other@5#tok", (None, "")),  # not a command label: no stamp, no token
    ],
)
def test_a_command_label_names_its_stamp_and_token(label: str, parts: tuple) -> None:
    assert command_parts(label) == parts
    assert command_stamp(label) == parts[0]


def test_clock_encodes_as_rosbags_does() -> None:
    msg = wire.clock()
    msg.clock.sec, msg.clock.nanosec = 12, 345
    assert codecs.CLOCK.encoder()(Stamp(12_000_000_345)) == wire.encode(msg)
    assert codecs.CLOCK.decode(wire.encode(msg)) == Stamp(12_000_000_345)


def test_big_endian_and_unknown_layouts_go_through_the_generic_codec() -> None:
    """A big-endian message (a peer that writes CDR_BE) is not for the packed readers: they
    decline it, and the codec decodes it with rosbags."""
    msg = wire.wrench_stamped("tool")
    _set_stamp(msg, 5_000_000)
    msg.wrench.force.x = 1.25
    big = bytes(wire.TYPESTORE.serialize_cdr(msg, msg.__msgtype__, little_endian=False))
    assert big[1] == 0 and cdr.read_vector(big) is None
    assert codecs.WRENCH.decode(big) == StampedVector(5_000_000, (1.25, 0.0, 0.0))
    js = wire.joint_state(["a", "b"], "x")
    js.position = np.array([1.0, 2.0])
    big = bytes(wire.TYPESTORE.serialize_cdr(js, js.__msgtype__, little_endian=False))
    assert cdr.JointReader()(big) is None
    assert codecs.JOINT_STATE.decode(big) == JointSample(0, ("a", "b"), (1.0, 2.0), (), ())


@pytest.mark.parametrize("cut", [3, 15, 20])
def test_a_truncated_message_is_declined_not_misread(cut: int) -> None:
    data = codecs.WRENCH.encoder("base_link")(StampedVector(1, (1.0, 2.0, 3.0)))
    assert cdr.read_vector(data[:cut]) is None
    js = codecs.JOINT_STATE.encoder("ee")(JointSample(1, ("slide",), (0.1,), (0.2,), (0.3,)))
    assert cdr.JointReader()(js[: cut + 10]) is None
