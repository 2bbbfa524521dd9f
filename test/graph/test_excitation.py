"""The identification input: a known excitation the environment adds, and a two-sided spring."""

from __future__ import annotations

import math

import pytest

from haptic_dob.core.control import ImpedanceLaw
from haptic_dob.core.cycle import wall_force
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.models.slide import SlideParams
from haptic_sim.hand import HandParams
from haptic_sim.slide.plant import SlideDeviceParams
from haptic_sim.slide.session import SessionConfig, run_session

SPRING = VirtualWall(stiffness_n_per_m=80.0, two_sided=True)


def test_step_and_sine_start_at_their_time_and_none_adds_nothing() -> None:
    step = Excitation("step", 2.4, at_s=1.0)
    assert [step.force_n(t) for t in (0.0, 0.999, 1.0, 5.0)] == [0.0, 0.0, 2.4, 2.4]
    sine = Excitation("sine", 0.6, at_s=0.5, frequency_hz=2.0)
    assert sine.force_n(0.4) == 0.0 and sine.force_n(0.5) == 0.0
    assert sine.force_n(0.625) == pytest.approx(0.6)  # a quarter period after the start
    assert not Excitation().active and Excitation().force_n(3.0) == 0.0
    assert (step.label(), sine.label()) == ("2.4 N step", "0.6 N 2 Hz sine")
    with pytest.raises(ValueError, match="kind must be one of none, step, sine"):
        Excitation("ramp", 1.0)


def test_a_two_sided_spring_pulls_back_too_and_a_wall_does_not() -> None:
    out, v = (-0.01, 0.0, 0.0), (0.0, 0.0, 0.0)
    assert SPRING.force(out, v) == pytest.approx((0.8, 0.0, 0.0))
    assert SPRING.force((0.01, 0.0, 0.0), v) == pytest.approx((-0.8, 0.0, 0.0))
    assert VirtualWall(stiffness_n_per_m=80.0).force(out, v) == (0.0, 0.0, 0.0)


def test_the_wall_stage_adds_the_excitation_along_the_normal_at_the_samples_time() -> None:
    wall = VirtualWall(stiffness_n_per_m=80.0, normal=(0.0, 0.0, 1.0), two_sided=True)
    step = Excitation("step", 2.0, at_s=1.0)
    p, v = (0.0, 0.0, 0.01), (0.0, 0.0, 0.0)
    assert wall_force(wall, p, v, step, 999_000_000) == pytest.approx((0.0, 0.0, -0.8))
    assert wall_force(wall, p, v, step, 1_000_000_000) == pytest.approx((0.0, 0.0, 1.2))
    assert wall_force(wall, p, v) == wall_force(wall, p, v, Excitation(), 5_000_000_000)


def test_a_step_under_the_spring_settles_at_step_over_stiffness_in_batch() -> None:
    """OL, no hand, a frictionless plant: the step response of the thesis's identification."""
    plant = SlideDeviceParams.matching(SlideParams(coulomb_n=0.0), encoder_resolution_m=1e-9)
    cfg = SessionConfig(
        device=plant,
        hand=HandParams(behaviour="none"),
        wall=SPRING,
        excitation=Excitation("step", 2.4, at_s=0.5),
        law=ImpedanceLaw("OL"),
    ).replace(loop__duration_s=10.0)
    r = run_session(cfg)
    # command k answers sample k (the step from sample 500 on); the effort of sample k is the
    # command of k-1, applied over [k-1, k)
    assert not r.effort[:501].any() and r.command[499] == 0.0
    assert r.command[500] == 2.4 and r.effort[501] == 2.4
    assert r.q[-1] == pytest.approx(2.4 / 80.0, abs=2e-6)
    # lightly damped: zeta = c / (2 sqrt(k m)) = 0.11, first peak near twice the final value
    zeta = 1.272 / (2.0 * math.sqrt(80.0 * 0.416))
    overshoot = math.exp(-zeta * math.pi / math.sqrt(1.0 - zeta * zeta))
    assert r.q.max() == pytest.approx(0.03 * (1.0 + overshoot), rel=0.02)


def test_the_environment_node_takes_the_excitation_at_run_time(context) -> None:
    from rclpy.parameter import Parameter

    from haptic_dob.nodes.environment_node import EnvironmentNode

    env = EnvironmentNode(context=context)
    try:
        ok = env.set_parameters(
            [
                Parameter("excitation.kind", value="step"),
                Parameter("excitation.amplitude_n", value=2.4),
                Parameter("two_sided", value=True),
            ]
        )
        assert all(r.successful for r in ok)
        assert env.excitation == Excitation("step", 2.4) and env.wall.two_sided
        res = env.set_parameters([Parameter("excitation.kind", value="ramp")])[0]
        assert not res.successful and "excitation.kind must be one of" in res.reason
        assert env.excitation.kind == "step"
    finally:
        env.destroy_node()


def test_the_environment_node_takes_an_excitation_along_each_axis(context) -> None:
    """A multisine per axis and a holding spring, set in one call; a step along the axes is
    refused with the reason and changes nothing."""
    from rclpy.parameter import Parameter

    from haptic_dob.nodes.environment_node import EnvironmentNode

    env = EnvironmentNode(context=context)
    try:
        ok = env.set_parameters_atomically(
            [
                Parameter("excitation.kind", value="multisine"),
                Parameter("excitation.amplitude_n", value=1.0),
                Parameter("excitation.along", value="axes"),
                Parameter("excitation.hold_n_per_m", value=150.0),
            ]
        )
        assert ok.successful, ok.reason
        want = Excitation("multisine", 1.0, along="axes", hold_n_per_m=150.0)
        assert env.excitation == want
        assert env.excitation.force(3.0, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)) == want.force(
            3.0, (1.0, 0.0, 0.0), (0.0, 0.0, 0.0)
        )
        res = env.set_parameters([Parameter("excitation.kind", value="step")])[0]
        assert not res.successful and "along axes needs a chirp or a multisine" in res.reason
        assert env.excitation == want
    finally:
        env.destroy_node()
