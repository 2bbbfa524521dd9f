"""Reading a model's joint vectors out of a JointState's fields (haptic_dob.core.joint_states)."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.joint_states import JointMap, joint_vectors

JOINTS = ("shoulder", "elbow")


def read(names, position, velocity=(), effort=(), previous=None, dt=1e-3):
    return joint_vectors(JointMap(JOINTS), names, position, velocity, effort, previous, dt)


def test_joints_are_matched_by_name_in_any_order_and_extra_joints_ignored() -> None:
    v = read(("gripper", "elbow", "shoulder"), (9.0, 2.0, 1.0), (9.0, 0.2, 0.1), (9.0, 20.0, 10.0))
    assert v == ([1.0, 2.0], [0.1, 0.2], [10.0, 20.0])


def test_a_message_without_names_is_in_model_order_and_must_have_every_joint() -> None:
    assert read((), np.array([1.0, 2.0])).q == [1.0, 2.0]
    with pytest.raises(ValueError, match="without names must have 2 values"):
        read((), (1.0, 2.0, 3.0))


def test_without_velocities_the_positions_are_differentiated() -> None:
    v = read(JOINTS, (1.0, 2.0), previous=[0.5, 2.5], dt=0.5)
    assert v.qd == [1.0, -1.0]
    assert read(JOINTS, (1.0, 2.0)).qd == [0.0, 0.0]  # nothing to differentiate from yet
    assert read(JOINTS, (1.0, 2.0)).tau == [0.0, 0.0]  # no efforts: zero effort


@pytest.mark.parametrize(
    ("names", "position", "velocity", "effort", "match"),
    [
        (("shoulder",), (1.0,), (), (), "lacks joint\\(s\\) elbow"),
        (JOINTS, (1.0, 2.0), (0.1,), (), "velocity has 1 values for 2 joints"),
        (JOINTS, (1.0, 2.0), (), (1.0, 2.0, 3.0), "effort has 3 values"),
        (JOINTS, (1.0, math.nan), (), (), "NaN or inf"),
        (JOINTS, (1.0, 2.0), (math.inf, 0.0), (), "NaN or inf"),
    ],
)
def test_unusable_messages_are_refused_with_the_reason(names, position, velocity, effort, match):
    with pytest.raises(ValueError, match=match):
        read(names, position, velocity, effort)


def test_the_map_follows_a_change_of_joint_order() -> None:
    joints = JointMap(JOINTS)
    assert joints.index(("shoulder", "elbow"), 2) == [0, 1]
    assert joints.index(("elbow", "shoulder"), 2) == [1, 0]
