"""Control laws (theory sheet section 2), force limits and joint mapping."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.control import (
    ControlMode,
    HandForce,
    ImpedanceController,
    ImpedanceLaw,
    joint_effort,
    limit_norm,
    saturate,
)
from haptic_dob.core.models import SlideModel

FW = (-2.0, 0.0, 0.0)  # the wall pushes the hand back with 2 N
FM = (1.5, 0.0, 0.0)  # the hand pushes 1.5 N into the wall (measured)
FE = (1.8, 0.0, 0.0)  # ... and 1.8 N (estimated)


def test_open_loop_renders_the_wall_force() -> None:
    assert ImpedanceLaw("OL", kf=5.0, max_force_n=10).force(FW, FM, FE) == FW


def test_closed_loop_feeds_back_the_measured_force() -> None:
    f = ImpedanceLaw("CL", kf=2.0, max_force_n=10).force(FW, FM, FE)
    assert f == pytest.approx((-2.0 + 2.0 * (-2.0 + 1.5), 0.0, 0.0))


def test_dob_feeds_back_the_estimated_force() -> None:
    f = ImpedanceLaw("DOB", kf=1.0, max_force_n=10).force(FW, FM, FE)
    assert f == pytest.approx((-2.0 + 1.0 * (-2.0 + 1.8), 0.0, 0.0))


def test_perfect_rendering_needs_no_correction() -> None:
    """When the hand force equals -F_w the loop adds nothing, whatever Kf."""
    for mode in ("CL", "DOB"):
        f = ImpedanceLaw(mode, kf=50.0, max_force_n=10).force(FW, (2.0, 0, 0), (2.0, 0, 0))
        assert f == pytest.approx(FW)


def test_force_norm_is_limited_with_direction_kept() -> None:
    f = ImpedanceLaw("OL", max_force_n=1.0).force((3.0, 4.0, 0.0), FM, FE)
    assert math.hypot(*f) == pytest.approx(1.0)
    assert f[0] / f[1] == pytest.approx(0.75)
    assert limit_norm((0.1, 0.2, 0.0), 1.0) == (0.1, 0.2, 0.0)


def test_mode_parsing_and_needs() -> None:
    assert ControlMode.parse("dob") is ControlMode.DOB
    assert ImpedanceLaw("CL").needs is HandForce.MEASURED
    assert ImpedanceLaw("DOB").needs is HandForce.ESTIMATED
    assert ImpedanceLaw("OL").needs is None
    with pytest.raises(ValueError, match="mode must be one of OL, CL, DOB"):
        ControlMode.parse("PID")


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"kf": -1.0}, "kf"),
        ({"kf": float("nan")}, "kf"),
        ({"max_force_n": 0.0}, "max_force_n"),
        ({"mode": "XL"}, "mode"),
    ],
)
def test_law_rejects_bad_settings(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        ImpedanceLaw(**kwargs)


def test_joint_mapping_is_the_jacobian_transpose() -> None:
    J = np.array([[0.1, 0.0], [0.0, 0.2], [0.3, 0.1]])
    assert joint_effort(J, (1.0, 2.0, 3.0)) == pytest.approx((J.T @ [1.0, 2.0, 3.0]).tolist())
    ctl = ImpedanceController(SlideModel(axis=(0.0, 1.0, 0.0)), ImpedanceLaw("OL", 0, 10))
    assert ctl.command([0.0], (0.0, -2.0, 5.0)) == pytest.approx([-2.0])


def test_law_swap_takes_effect_on_the_next_command() -> None:
    ctl = ImpedanceController(SlideModel(), ImpedanceLaw("OL", 0.0, 10))
    assert ctl.command([0.0], FW, FM, FE) == [-2.0]
    ctl.law = ImpedanceLaw("CL", 2.0, 10)
    assert ctl.command([0.0], FW, FM, FE) == pytest.approx([-3.0])


def test_saturation_clips_per_joint_and_refuses_nan() -> None:
    assert saturate([5.0, -5.0, 1.0], 4.0) == [4.0, -4.0, 1.0]
    assert saturate([5.0, -5.0], [1.0, 2.0]) == [1.0, -2.0]
    with pytest.raises(ValueError, match="effort"):
        saturate([float("nan")], 4.0)
    with pytest.raises(ValueError, match="limit"):
        saturate([1.0], 0.0)
