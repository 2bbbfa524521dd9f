"""The loop's joint efforts in the driver's command space and back, clamped and rate-limited."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.bridge.command import CommandLimiter, CommandMap
from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.core.models.phantom import PhantomModel


def driver(**values: object) -> DriverSettings:
    return DriverSettings.of({"state.topic": "s", "command.topic": "c", **values})


def test_joint_efforts_in_the_controllers_order_a_joint_it_lacks_gets_zero() -> None:
    model = PhantomModel("appendix_b", gravity=False)  # 3 joints
    names = ("a", "b", "c")
    m = CommandMap(
        driver(**{"command.joints": ["c", "gripper", "a", "b"], "state.signs": [1.0, -1.0, 1.0]}),
        model,
        names,
    )
    u = m.forward((1.0, 2.0, 3.0), model.home)
    assert u == (3.0, 0.0, 1.0, -2.0)
    assert m.back(u, model.home) == (1.0, 2.0, 3.0)
    partial = CommandMap(driver(**{"command.joints": ["a", "b"]}), model, names)
    assert partial.unsent == ("c",) and partial.back(
        partial.forward((1, 2, 3), model.home), model.home
    ) == (1.0, 2.0, 0.0)
    with pytest.raises(ValueError, match="twice"):
        CommandMap(driver(**{"command.joints": ["a", "a"]}), model, names)


def test_a_force_command_through_j_inverse_transpose_on_the_drivers_axes() -> None:
    model = PhantomModel("appendix_b", gravity=False)
    d = driver(
        **{"profile": "cartesian_wrench", "frame.axes": [0, 2, 1], "frame.signs": [1.0, -1.0, 1.0]}
    )
    m = CommandMap(d, model, model.joint_names)
    q = np.array(model.home)
    F = np.array([0.5, -1.0, 2.0])  # model axes
    tau = model.jacobian(q).T @ F
    u = m.forward(tuple(tau), q)
    assert u == pytest.approx((0.5, 2.0, 1.0))  # driver (x, y, z) = model (x, z, -y)
    assert m.back(u, q) == pytest.approx(tuple(tau))  # square J: exact both ways


def test_the_limiter_clamps_each_element_and_its_change_but_never_slows_a_stop() -> None:
    lim = CommandLimiter([1.0, 2.0], [1000.0, 0.0], period_s=0.001)  # 1 N per period on the first
    assert lim.limit([5.0, -5.0]) == (1.0, -2.0)
    assert lim.clamped == 1 and lim.slowed == 0
    lim.zero()
    assert lim.limit([0.5, 1.5]) == (0.5, 1.5)
    assert lim.limit([-1.0, 1.5]) == pytest.approx((-0.5, 1.5))  # at most 1 N per period
    assert lim.slowed == 1
    assert lim.zero() == (0.0, 0.0) and lim.last == (0.0, 0.0)
