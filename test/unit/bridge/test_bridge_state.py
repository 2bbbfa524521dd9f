"""A driver's state in the model's terms: joints by name, signs and units, the velocity filled."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.bridge.driver_settings import FrameSettings
from haptic_dob.bridge.state import StateReader
from haptic_dob.bridge.state_settings import StateSettings
from haptic_dob.bridge.velocity import VelocityFilter

MODEL = ("phi1", "phi2", "phi3")
TOUCH = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")


def reader(**state: object) -> StateReader:
    settings = StateSettings(**{"topic": "/touch/joint_states", **state})  # type: ignore[arg-type]
    return StateReader(settings, FrameSettings(), MODEL, 0.002)


def test_joints_by_name_in_any_order_with_extra_joints_signs_and_units() -> None:
    r = reader(joints=["waist", "shoulder", "elbow"], signs=[1.0, -1.0, 1.0], scale=0.001)
    names = ("roll", "elbow", "pitch", "waist", "yaw", "shoulder")  # the gimbal too
    s = r.joints(5, names, [9.0, 3.0, 9.0, 1.0, 9.0, 2.0], [0.0, 30.0, 0, 10.0, 0, 20.0], [])
    assert s.q == pytest.approx((0.001, -0.002, 0.003))
    assert s.qd == pytest.approx((0.01, -0.02, 0.03))  # the driver's, same signs and units
    assert s.effort is None
    with pytest.raises(ValueError, match="lacks joint"):
        r.joints(6, ("waist", "elbow"), [0.0, 0.0], [], [])
    with pytest.raises(ValueError, match="NaN"):
        r.joints(7, TOUCH[:3], [math.nan, 0.0, 0.0], [], [])


def test_a_position_only_state_is_differenced_and_low_passed() -> None:
    r = reader(joints=["waist", "shoulder", "elbow"], velocity_cutoff_hz=0.0)
    assert r.joints(0, TOUCH[:3], [0.0, 0.0, 0.0], [], []).qd == (0.0, 0.0, 0.0)
    s = r.joints(2_000_000, TOUCH[:3], [0.002, 0.0, -0.004], [], [])  # 2 ms later
    assert s.qd == pytest.approx((1.0, 0.0, -2.0))
    f = VelocityFilter(cutoff_hz=50.0, max_gap_s=0.01)
    dt = 0.002
    alpha = 1.0 - math.exp(-2 * math.pi * 50.0 * dt)
    f.update(0, [0.0])
    v = [f.update(round(k * dt * 1e9), [k * dt * 0.1])[0] for k in range(1, 200)]
    assert v[0] == pytest.approx(alpha * 0.1)  # a first-order step toward 0.1 m/s
    assert v[-1] == pytest.approx(0.1)
    assert f.update(round(1.0 * 1e9), [0.0]) == (0.0,)  # a gap past max_gap_s starts again


def test_the_driver_velocity_is_used_only_where_asked() -> None:
    r = reader(joints=["waist", "shoulder", "elbow"], velocity="difference", velocity_cutoff_hz=0)
    r.joints(0, TOUCH[:3], [0.0, 0.0, 0.0], [5.0, 5.0, 5.0], [])
    s = r.joints(1_000_000, TOUCH[:3], [0.001, 0.0, 0.0], [5.0, 5.0, 5.0], [1.0, 2.0, 3.0])
    assert s.qd == pytest.approx((1.0, 0.0, 0.0)) and s.effort == (1.0, 2.0, 3.0)
    with pytest.raises(ValueError, match="no velocity"):
        reader(joints=["waist", "shoulder", "elbow"], velocity="driver").joints(
            0, TOUCH[:3], [0.0, 0.0, 0.0], [], []
        )


def test_a_pose_state_on_the_drivers_axes() -> None:
    r = StateReader(
        StateSettings(topic="p", type="pose", scale=0.001, velocity_cutoff_hz=0.0),
        FrameSettings(axes=[0, 2, 1], signs=[1.0, -1.0, 1.0]),
        ("x", "y", "z"),
        0.001,
    )
    s = r.position(0, (10.0, 20.0, 30.0))  # driver mm: model (x, -z, y)
    assert s.q == pytest.approx((0.010, -0.030, 0.020))
    with pytest.raises(ValueError, match="3-axis"):
        StateReader(StateSettings(type="pose"), FrameSettings(), ("a", "b"), 0.001)
    assert np.allclose(r.position(1_000_000, (11.0, 20.0, 30.0)).qd, (1.0, 0.0, 0.0))
