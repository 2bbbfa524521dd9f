"""The simulated multi-DOF arm: cycle contract, actuators, encoders, 3-D hand, sensor, runner."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.control import ImpedanceLaw
from haptic_dob.core.models import PhantomModel, SlideModel, UrdfModel
from haptic_dob.core.models.phantom import HOME
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from haptic_sim.arm.session import ArmSessionConfig, run_arm_session
from haptic_sim.device.factory import build_device, simulation_specs
from haptic_sim.hand import HandParams
from haptic_sim.sensor import ForceSensorParams
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.session import LoopSettings

ROOT = Path(__file__).resolve().parents[2]
IDEAL = ArmDeviceParams(encoder_resolution_rad=0.0)


def test_cycle_contract_and_phantom_force_limits() -> None:
    dev = SimulatedArm(PhantomModel())
    s0 = dev.sample()
    assert (s0.k, s0.stamp_ns, s0.qd, s0.effort) == (0, 0, (0.0, 0.0, 0.0), (0.0, 0.0, 0.0))
    np.testing.assert_allclose(s0.q, HOME, atol=1.5e-4 / 2)
    np.testing.assert_allclose(s0.ee_position, [0.178, 0.0, -0.221], atol=1e-4)
    # 8.5 N at the tip at home: lever arms r = l1 = 0.178 m, l1, le4 = 0.221 m
    np.testing.assert_allclose(dev.max_effort, [8.5 * 0.178, 8.5 * 0.178, 8.5 * 0.221], rtol=1e-9)
    dev.apply([10.0, -10.0, 0.5])
    s1 = dev.sample()
    assert s1.k == 1 and s1.stamp_ns == 1_000_000
    assert s1.effort == pytest.approx((8.5 * 0.178, -8.5 * 0.178, 0.5))
    for bad in ([0.0, 0.0], [0.0, math.nan, 0.0], [0.0, math.inf, 0.0]):
        with pytest.raises(ValueError, match="effort"):
            dev.apply(bad)
    assert dev.k == 1


def test_encoder_quantizes_and_velocity_is_the_backward_difference() -> None:
    res = 1e-3
    dev = SimulatedArm(PhantomModel(), ArmDeviceParams(encoder_resolution_rad=res))
    prev = np.array(dev.sample().q)
    for _ in range(30):
        dev.apply([0.0, 0.0, 0.0])  # falls under gravity
        s = dev.sample()
        q = np.array(s.q)
        np.testing.assert_allclose(q / res, np.round(q / res), atol=1e-9)
        assert np.max(np.abs(q - dev.q)) <= res / 2 + 1e-12
        np.testing.assert_allclose(s.qd, (q - prev) / dev.dt, rtol=1e-12, atol=1e-9)
        prev = q
    exact = SimulatedArm(
        PhantomModel(), ArmDeviceParams(encoder_resolution_rad=0.0, velocity="exact")
    )
    for _ in range(30):
        exact.apply([0.0, 0.0, 0.0])
    np.testing.assert_array_equal(exact.sample().qd, exact.v)


def test_encoder_matrix_counts_a_joint_as_a_difference_of_two_encoders() -> None:
    """A Touch's elbow: HD joint 2 counts shoulder + elbow; the elbow is two counts apart."""
    res = 1e-3
    E = [1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 1.0]
    dev = SimulatedArm(
        PhantomModel(), ArmDeviceParams(encoder_resolution_rad=res, encoder_matrix=E)
    )
    off_own_count = 0
    for _ in range(60):
        dev.apply([0.0, 0.0, 0.0])  # falls under gravity
        q = np.array(dev.sample().q)
        hd = np.array(E).reshape(3, 3) @ q  # what the encoders read: whole counts
        np.testing.assert_allclose(hd / res, np.round(hd / res), atol=1e-9)
        assert np.max(np.abs(hd - np.array(E).reshape(3, 3) @ dev.q)) <= res / 2 + 1e-12
        # the elbow is a difference of two rounded counts: up to a whole count off its motion
        assert abs(q[2] - dev.q[2]) <= res + 1e-12
        off_own_count += abs(q[2] - dev.q[2]) > res / 2 + 1e-12
    assert off_own_count > 0  # it did lie more than half a count off, as one encoder cannot
    for bad in ([1.0, 0.0], [1.0, 0.0, 0.0, 1.0, 0.0, 0.0, 1.0, 0.0, 0.0], [math.nan] * 9):
        with pytest.raises(ValueError, match="encoder_matrix"):
            SimulatedArm(PhantomModel(), ArmDeviceParams(encoder_matrix=bad))


def test_effort_limits_from_parameters_and_from_the_urdf() -> None:
    dev = SimulatedArm(PhantomModel(), ArmDeviceParams(joint_effort_limits=[0.5, 0.6, 0.7]))
    assert dev.max_effort == (0.5, 0.6, 0.7)
    arm = SimulatedArm(UrdfModel(ROOT / "config/urdf/arm3.urdf", "tool"))
    assert arm.max_effort == (20.0, 20.0, 10.0)
    with pytest.raises(ValueError, match="joint_effort_limits"):
        SimulatedArm(PhantomModel(), ArmDeviceParams(joint_effort_limits=[1.0, 1.0]))
    with pytest.raises(ValueError, match="initial_position"):
        SimulatedArm(PhantomModel(), ArmDeviceParams(initial_position=[0.0]))


def test_push_hold_hand_pulls_the_end_effector_along_its_direction() -> None:
    """Gravity-free PHANToM (Cavusoglu), u = (1, 1, -1)/sqrt 3. Free: the grip drags the tip to
    the held reference ``p0 + offset u``. Held by stiff joint servos: the hand pushes with
    about ``k_h offset`` = 3 N along u (the force on the device, + along the push)."""
    u = np.array([1.0, 1.0, -1.0]) / math.sqrt(3.0)
    hand = HandParams(behaviour="push_hold", offset_m=0.01, ramp_s=0.2, damping_n_s_per_m=10.0)
    device = ArmDeviceParams(
        encoder_resolution_rad=0.0, hand_direction=tuple(u), initial_position=[0.0, 0.0, 1.2]
    )
    model = PhantomModel("cavusoglu", gravity=False)
    free = SimulatedArm(model, device, hand=hand)
    p0 = np.array(free.sample().ee_position)
    for _ in range(1000):
        free.apply([0.0, 0.0, 0.0])
    np.testing.assert_allclose(np.array(free.sample().ee_position) - p0, 0.01 * u, atol=1e-5)
    assert np.linalg.norm(free.sample().hand_force) < 1e-3
    held = SimulatedArm(model, device, hand=hand)
    q0 = np.array(device.initial_position)
    for _ in range(1000):
        s = held.sample()
        held.apply((-200.0 * (np.array(s.q) - q0) - 2.0 * np.array(s.qd)).tolist())
    f = np.array(held.sample().hand_force)
    assert 2.5 < f @ u < 3.0  # measured 2.83 N: 3 N less the servos' give
    assert np.linalg.norm(f - (f @ u) * u) < 0.05 * (f @ u)  # measured 2.1 %


def test_lateral_semi_random_motion_moves_across_the_push() -> None:
    """Semi-random motion across u only (no push, no motion along u): the tip wanders sideways."""
    u = np.array([0.0, 0.0, -1.0])

    def spread(amplitude: float) -> tuple[float, float]:
        hand = HandParams(behaviour="semi_random", offset_m=0.0, amplitude_m=0.0, ramp_s=0.1)
        dev = SimulatedArm(
            PhantomModel("cavusoglu", gravity=False),
            ArmDeviceParams(encoder_resolution_rad=0.0, hand_lateral_amplitude_m=amplitude),
            hand=hand,
            seed=4,
        )
        xs = []
        for _ in range(600):
            dev.apply([0.0, 0.0, 0.0])
            xs.append(dev.sample().ee_position)
        xs = np.array(xs) - xs[0]
        along = xs @ u
        return float(np.max(np.abs(xs - np.outer(along, u)))), float(np.max(np.abs(along)))

    assert spread(0.0) == (0.0, 0.0)
    across, along = spread(0.003)
    assert across > 2e-3  # measured 7.1 mm
    assert along < 0.1 * across  # measured 0.02 mm: the arm's coupling only


def test_force_sensor_reads_the_external_tip_force() -> None:
    force = np.array([0.5, -0.2, 1.0])
    dev = SimulatedArm(
        PhantomModel(gravity=False),
        ArmDeviceParams(
            encoder_resolution_rad=0.0, external_force_n=tuple(force), external_force_at_s=0.01
        ),
        sensor=ForceSensorParams(noise_std_n=0.0),
    )
    readings, truth = [], []
    for _ in range(40):
        dev.apply([0.0, 0.0, 0.0])
        s = dev.sample()
        readings.append(s.wrench_measured)
        truth.append(s.hand_force)
    assert np.array_equal(truth[5], np.zeros(3)) and np.array_equal(truth[-1], force)
    np.testing.assert_allclose(readings[-1], force, atol=1e-6)  # 500 Hz sensor settled


def test_generic_model_without_pinocchio_one_pass_still_simulates() -> None:
    """SimulatedArm takes any DeviceModel; the 1-DOF slide model runs through the generic path."""
    dev = SimulatedArm(SlideModel(coulomb_n=0.0), ArmDeviceParams(encoder_resolution_rad=0.0))
    for _ in range(100):
        dev.apply([1.0])
    # m x'' = 1 - b x': velocity after 0.1 s
    m, b = 0.416, 1.272
    assert dev.v[0] == pytest.approx((1 / b) * (1 - math.exp(-b * 0.1 / m)), rel=1e-8)


def test_factory_builds_the_phantom_and_keeps_the_slide() -> None:
    names = {s.name for s in simulation_specs()}
    assert {"arm.max_force_n", "arm.encoder_resolution_rad", "arm.initial_position"} <= names
    assert isinstance(build_device({}), SimulatedSlide)
    dev = build_device({"model": "phantom", "arm.max_force_n": 4.0, "hand.behaviour": "none"})
    assert isinstance(dev, SimulatedArm) and dev.dof == 3
    np.testing.assert_allclose(dev.max_effort, [4.0 * 0.178, 4.0 * 0.178, 4.0 * 0.221])
    urdf = build_device(
        {"model": "urdf", "urdf_path": str(ROOT / "config/urdf/arm3.urdf"), "tip_frame": "tool"}
    )
    assert urdf.dof == 3 and urdf.model.joint_names == ("joint1", "joint2", "joint3")


def test_batch_run_is_deterministic_and_exact_mode_uses_the_true_disturbance() -> None:
    force = (0.3, 0.0, -0.4)
    cfg = ArmSessionConfig(
        loop=LoopSettings(duration_s=0.2, seed=3),
        plant=PhantomModel(),
        device=ArmDeviceParams(external_force_n=force, velocity="exact"),
        hand=HandParams(behaviour="semi_random"),
        law=ImpedanceLaw("DOB", 1.0, 8.5),
        observer=ObserverSettings(2.0, 0.0),
    )
    a, b = run_arm_session(cfg), run_arm_session(cfg)
    for name in ("q", "effort", "force_estimated", "tip_force"):
        np.testing.assert_array_equal(getattr(a, name), getattr(b, name))
    exact = run_arm_session(cfg.replace(exact_force=True))
    # exact mode with the plant as the observer's model: the DOB input is the true tip force
    np.testing.assert_allclose(exact.force_used[2:], exact.tip_force[2:], atol=1e-9)
    np.testing.assert_allclose(
        exact.d_exact,
        np.array(
            [
                PhantomModel().jacobian(q).T @ f
                for q, f in zip(exact.q_true, exact.tip_force, strict=True)
            ]
        ),
        atol=1e-12,
    )


def test_phantom_config_loads_for_the_batch_runner() -> None:
    cfg = ArmSessionConfig.from_yaml(ROOT / "config" / "phantom_sim.yaml")
    assert cfg.plant.gravity_enabled and not cfg.observer_model.gravity_enabled
    assert cfg.law.kf == 1.0 and cfg.wall.stiffness_n_per_m == 1000.0
    np.testing.assert_allclose(
        cfg.wall.position, cfg.plant.forward_kinematics(HOME) - [0, 0, 0.01], atol=1e-12
    )
    r = run_arm_session(cfg, cycles=100)
    assert r.ee_true[-1, 2] < r.ee_true[0, 2]  # falling toward the wall


def test_device_node_builds_and_steps_the_phantom(monkeypatch: pytest.MonkeyPatch) -> None:
    import rclpy
    from rclpy.context import Context

    from haptic_dob.nodes.observer_node import ObserverNode
    from haptic_sim.nodes.device_node import DeviceNode
    from support.rosgraph import isolated_env

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    args = ["--ros-args", "-p", "model:=phantom", "-p", "hand.behaviour:=none"]
    rclpy.init(context=ctx, args=args)
    try:
        node = DeviceNode(context=ctx)
        obs = ObserverNode(context=ctx)
        try:
            assert isinstance(node.device, SimulatedArm) and node.dof == 3
            assert node.limits == node.device.max_effort
            node._advance([0.1, 0.2, 0.3])
            assert node.device.k == 1 and node.device.sample().effort == (0.1, 0.2, 0.3)
            assert isinstance(obs.model, PhantomModel) and obs.model.joint_names == (
                "phi1",
                "phi2",
                "phi3",
            )
        finally:
            node.destroy_node()
            obs.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)
