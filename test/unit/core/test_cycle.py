"""The cycle written once (``haptic_dob.core.cycle``): the join of command k's inputs, ROS-free."""

from __future__ import annotations

import pytest

from haptic_dob.core.command_join import WARM_SAMPLES, CommandJoin
from haptic_dob.core.control import ControlMode, ImpedanceController, ImpedanceLaw
from haptic_dob.core.cycle import LoopCycle, estimate, wall_force
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models import SlideModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.session import SessionConfig

T = 1_000_000  # ns
X = (1.0, 0.0, 0.0)


def join(mode: str = "OL", kf: float = 1.0, **kw) -> CommandJoin:
    law = ImpedanceLaw(ControlMode.parse(mode), kf, 4.0)
    return CommandJoin(ImpedanceController(SlideModel(), law), T, needs_q=False, **kw)


def f(x: float) -> tuple[float, float, float]:
    return (x, 0.0, 0.0)


def test_ol_commands_on_the_wall_force_alone() -> None:
    j = join("OL")
    assert j.wall(0, f(-1.0)) == [-1.0]
    assert j.estimated(0, f(0.5)) is None  # OL never waits for, nor answers, an estimate


@pytest.mark.parametrize(("mode", "feed"), [("CL", "measured"), ("DOB", "estimated")])
def test_a_force_mode_waits_for_its_input_of_the_same_stamp(mode: str, feed: str) -> None:
    j = join(mode, kf=2.0)
    assert j.wall(0, f(-1.0)) is None  # waiting for the hand force of stamp 0
    assert j.missing_inputs() == ["wrench_measured" if feed == "measured" else "wrench_estimate"]
    assert getattr(j, feed)(0, f(0.25)) == [-1.0 + 2.0 * (-1.0 + 0.25)]
    assert not j.pending() and j.missing_inputs() == []


def test_a_repeated_sample_gets_the_same_command_and_a_stale_one_none() -> None:
    j = join("OL")
    first = j.wall(T, f(-2.0))
    assert j.wall(T, f(-2.0)) is first
    assert j.wall(0, f(-9.0)) is None


def test_jacobian_inputs_join_by_stamp_too() -> None:
    model = build_model({"model": "phantom"})
    j = CommandJoin(ImpedanceController(model, ImpedanceLaw()), T, needs_q=True)
    assert j.wall(0, f(1.0)) is None and j.missing_inputs() == ["joint_states"]
    tau = j.joints(0, [0.0, 0.0, 1.5707963])
    assert tau is not None and len(tau) == 3


def test_a_switch_needs_its_input_flowing_then_waits_for_it_while_it_catches_up() -> None:
    j = join("OL")
    dob = ImpedanceLaw(ControlMode.DOB, 1.0, 4.0)
    with pytest.raises(ValueError, match="needs wrench_estimate, which is not flowing"):
        j.check_switch(dob)
    for k in range(WARM_SAMPLES):  # the observer 10 cycles behind the wall
        j.wall((k + 10) * T, f(-1.0))
        j.estimated(k * T, f(0.5))
    j.check_switch(dob)
    j.set_law(dob)
    assert j.wall(30 * T, f(-1.0)) is None  # waits: the estimate is coming, not lost
    for k in range(WARM_SAMPLES, 30):
        assert j.estimated(k * T, f(0.5)) is None
    assert j.estimated(30 * T, f(0.5)) == [-1.0 + (-1.0 + 0.5)]
    assert j.fallbacks == 0


@pytest.mark.parametrize(("fallback", "expected"), [("zero", [0.0]), ("OL", [-1.0])])
def test_a_silent_input_falls_back_and_flowing_again_returns(fallback, expected) -> None:
    warned, told = [], []
    j = join("DOB", input_timeout_ns=5 * T, fallback=fallback, warn=warned.append, info=told.append)
    for k in range(30):
        j.estimated(k * T, f(0.5))
        assert j.wall(k * T, f(-1.0)) is not None
    for k in range(30, 35):  # the estimate stops; within the timeout the join waits
        assert j.wall(k * T, f(-1.0)) is None
    assert j.wall(35 * T, f(-1.0)) == expected  # 6 ms of samples after the last one: > 5
    assert j.fallback_reason and "wrench_estimate silent for 6 ms" in j.fallback_reason
    assert warned and "rendering " + fallback in warned[0]
    for k in range(36, 36 + WARM_SAMPLES):  # flowing again: back to DOB
        j.estimated(k * T, f(0.5))
        out = j.wall(k * T, f(-1.0))
    assert j.fallback_reason is None and out == [-1.5] and told


def test_an_input_not_received_yet_is_waited_for_from_the_first_cycle() -> None:
    """Stamps of a driver's clock (ns since 1970): the first estimate is on its way, not silent
    since time zero (it once fell back at the first sample, "silent for 1795934945722 ms")."""
    warned: list[str] = []
    j = join("DOB", input_timeout_ns=5 * T, warn=warned.append)
    t0 = 1_795_934_945_722_000_000
    assert j.wall(t0, f(-1.0)) is None  # waits for the estimate of this sample
    assert j.estimated(t0, f(0.5)) == [-1.5] and j.fallbacks == 0
    j = join("DOB", input_timeout_ns=5 * T, warn=warned.append)
    for k in range(6):
        assert j.wall(t0 + k * T, f(-1.0)) is None
    assert j.wall(t0 + 6 * T, f(-1.0)) == [0.0]
    assert warned == [
        "DOB (Kf 1) lost its input (wrench_estimate not received in the first 6 ms of samples): "
        "rendering zero until it flows again"
    ]


def test_the_batch_cycle_is_the_three_stages_in_order() -> None:
    """``LoopCycle.step`` computes exactly what the stages give one by one (as the nodes do)."""
    cfg = SessionConfig()
    model = cfg.model.model()
    law = ImpedanceLaw(ControlMode.DOB, 1.0, 4.0)
    wall = VirtualWall(800.0)
    cycle = LoopCycle(
        wall, DisturbanceObserver(model, 41.6, 1e-3, 4.0), ImpedanceController(model, law), T
    )
    observer = DisturbanceObserver(model, 41.6, 1e-3, 4.0)
    controller = ImpedanceController(model, law)
    device = SimulatedSlide(cfg.device, cfg.sensor, cfg.hand, 1000.0, 10, 0)
    for _ in range(2000):
        s = device.sample()
        got = cycle.step(
            s.stamp_ns, s.q, s.qd, s.effort, s.ee_position, s.ee_velocity, s.wrench_measured
        )
        f_wall = wall_force(wall, s.ee_position, s.ee_velocity)
        f_est = estimate(observer, s.q, s.qd, s.effort)
        assert got.wall_force == f_wall and got.estimated_force == f_est
        assert got.command == controller.command(s.q, f_wall, s.wrench_measured, f_est)
        device.apply(got.command)
