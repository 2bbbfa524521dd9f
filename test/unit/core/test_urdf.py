"""URDF arms: the model against closed forms, joint selection and order, errors, tip force."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from support.arm3 import ARM3, GAIN, check_known_force, known_force_run

ROOT = Path(__file__).resolve().parents[3]
ARM7 = ROOT / "config" / "urdf" / "arm7.urdf"
G0 = 9.81


def arm3_closed_form(q):
    """End-effector point and gravity of arm3.urdf, from its numbers (not from pinocchio).

    joint1 about z at height 0.05, joint2 0.1 above it, both pitch joints about +y (a rotation by
    q about +y takes x to (cos q, 0, -sin q)); links 0.35 and 0.3 m; rods of 1.2 and 0.8 kg with
    centres at half length, a 0.05 kg tool at the tip.
    """
    q1, q2, q3 = q
    a2, a23 = q2, q2 + q3
    reach = 0.35 * math.cos(a2) + 0.3 * math.cos(a23)
    p = np.array(
        [
            reach * math.cos(q1),
            reach * math.sin(q1),
            0.15 - 0.35 * math.sin(a2) - 0.3 * math.sin(a23),
        ]
    )
    # V = g * sum(m z): z of link2's centre -0.175 s2, link3's -0.35 s2 - 0.15 s23, tool's tip
    dV2 = G0 * (
        -1.2 * 0.175 * math.cos(a2)
        + 0.8 * (-0.35 * math.cos(a2) - 0.15 * math.cos(a23))
        + 0.05 * (-0.35 * math.cos(a2) - 0.3 * math.cos(a23))
    )
    dV3 = G0 * (0.8 * -0.15 * math.cos(a23) + 0.05 * -0.3 * math.cos(a23))
    return p, np.array([0.0, dV2, dV3])


def test_arm3_kinematics_and_gravity_match_the_closed_form() -> None:
    model = UrdfModel(ARM3, "tool")
    assert model.joint_names == ("joint1", "joint2", "joint3")
    assert model.effort_limits == (20.0, 20.0, 10.0)
    rng = np.random.default_rng(2)
    h = 1e-6
    for q in rng.uniform(-math.pi, math.pi, (50, 3)):
        p, G = arm3_closed_form(q)
        np.testing.assert_allclose(model.forward_kinematics(q), p, atol=1e-12)
        np.testing.assert_allclose(model.gravity(q), G, atol=1e-12)
        J_fd = np.column_stack(
            [
                (arm3_closed_form(q + h * e)[0] - arm3_closed_form(q - h * e)[0]) / (2 * h)
                for e in np.eye(3)
            ]
        )
        np.testing.assert_allclose(model.jacobian(q), J_fd, atol=1e-8)
        D = model.mass_matrix(q)
        assert np.allclose(D, D.T, rtol=0, atol=1e-15) and np.linalg.eigvalsh(D)[0] > 0


def test_arm3_simulation_conserves_energy() -> None:
    """Torque-free, frictionless, gravity on: the potential from the closed form (via G), the
    kinetic energy from the model's D. Measured drift over 1 s: 4.8e-13 J (kinetic energy
    up to 5 J); bound 1e-8 J."""
    model = UrdfModel(ARM3, "tool")
    dev = SimulatedArm(
        model, ArmDeviceParams(encoder_resolution_rad=0.0, initial_position=[0.2, 0.3, -0.5])
    )

    def potential(q) -> float:  # V up to a constant, integrated from the closed-form G
        _, q2, q3 = q
        return G0 * (
            -1.2 * 0.175 * math.sin(q2)
            + 0.8 * (-0.35 * math.sin(q2) - 0.15 * math.sin(q2 + q3))
            + 0.05 * (-0.35 * math.sin(q2) - 0.3 * math.sin(q2 + q3))
        )

    for _ in range(20):
        dev.apply([1.0, 0.0, 0.0])
    e0 = dev.kinetic_energy() + potential(dev.q)
    drift = 0.0
    for _ in range(1000):
        dev.apply([0.0, 0.0, 0.0])
        drift = max(drift, abs(dev.kinetic_energy() + potential(dev.q) - e0))
    assert dev.kinetic_energy() > 0.1
    assert drift < 1e-8, drift


def test_string_and_path_give_the_same_model_and_joint_order_is_ours() -> None:
    a = UrdfModel(ARM3, "tool")
    b = UrdfModel(ARM3.read_text(), "tool")
    q, qd = np.array([0.3, -0.4, 0.9]), np.array([0.5, -1.0, 2.0])
    np.testing.assert_array_equal(a.mass_matrix(q), b.mass_matrix(q))
    shuffled = UrdfModel(str(ARM3), "tool", ["joint3", "joint1", "joint2"])
    assert shuffled.joint_names == ("joint3", "joint1", "joint2")
    perm = [2, 0, 1]
    D, h = shuffled.mass_and_bias(q[perm], qd[perm])
    D0, h0 = a.mass_and_bias(q, qd)
    np.testing.assert_allclose(D, D0[np.ix_(perm, perm)], atol=1e-15)
    np.testing.assert_allclose(h, h0[perm], atol=1e-14)
    np.testing.assert_allclose(shuffled.jacobian(q[perm]), a.jacobian(q)[:, perm], atol=1e-15)
    assert shuffled.effort_limits == (10.0, 20.0, 20.0)


def test_a_subset_of_joints_locks_the_others_at_zero() -> None:
    full = UrdfModel(ARM3, "tool")
    two = UrdfModel(ARM3, "tool", ["joint2", "joint3"])
    assert two.dof == 2
    q = np.array([0.4, -0.7])
    np.testing.assert_allclose(
        two.forward_kinematics(q), full.forward_kinematics([0.0, *q]), atol=1e-15
    )
    np.testing.assert_allclose(two.gravity(q), full.gravity([0.0, *q])[1:], atol=1e-14)


def test_seven_dof_arm_loads_and_its_observer_wrench_stays_bounded_when_singular() -> None:
    m = UrdfModel(ARM7, "tool")
    assert m.dof == 7 and m.joint_names[-1] == "joint7"
    obs = DisturbanceObserver(m, 5.0, 1e-3)
    q = np.zeros(7)  # stretched straight up: J has rank 2
    assert np.linalg.svd(m.jacobian(q), compute_uv=False)[-1] < 1e-12
    obs.update(q, np.zeros(7), np.zeros(7))
    for _ in range(50):
        obs.update(q, np.zeros(7), np.full(7, -0.5))
    f = obs.wrench(q)
    assert np.all(np.isfinite(f)) and np.linalg.norm(f) < 1e3


@pytest.mark.parametrize(
    ("args", "message"),
    [
        ((ARM3, "gripper"), "tip_frame 'gripper' is not a frame"),
        ((ARM3, "tool", ["joint1", "elbow"]), "joint_names: elbow not movable"),
        ((ARM3, "tool", ["joint1", "joint1"]), "lists a joint twice"),
        (("/no/such/arm.urdf", "tool"), "no such file"),
        (("<robot name='x'><link name='a'/></robot", "tool"), "cannot parse|not a frame"),
        ((ARM3, ""), "tip_frame must name"),
    ],
)
def test_urdf_model_errors_are_clear(args, message: str) -> None:
    with pytest.raises(ValueError, match=message):
        UrdfModel(*args)


def test_factory_builds_urdf_and_phantom_models_from_parameters() -> None:
    names = {s.name for s in model_specs()}
    assert {"robot_description", "urdf_path", "tip_frame", "joint_names", "urdf.gravity"} <= names
    assert {"phantom.params", "phantom.gravity"} <= names
    m = build_model({"model": "urdf", "robot_description": ARM3.read_text(), "tip_frame": "tool"})
    assert isinstance(m, UrdfModel) and m.dof == 3
    m = build_model(
        {
            "model": "urdf",
            "urdf_path": str(ARM3),
            "tip_frame": "tool",
            "joint_names": ["joint2", "joint3"],
            "urdf.gravity": False,
        }
    )
    assert m.dof == 2 and not m.gravity_enabled
    with pytest.raises(ValueError, match=r"robot_description .* or urdf_path"):
        build_model({"model": "urdf", "tip_frame": "tool"})
    with pytest.raises(ValueError, match="needs tip_frame"):
        build_model({"model": "urdf", "urdf_path": str(ARM3)})
    p = build_model({"model": "phantom", "phantom.params": "cavusoglu", "phantom.gravity": False})
    assert p.params.name == "cavusoglu" and not p.gravity_enabled
    with pytest.raises(ValueError, match=r"phantom\.params must be one of"):
        build_model({"model": "phantom", "phantom.params": "omni"})


def test_observer_recovers_a_known_tip_force_within_the_predicted_lag() -> None:
    samples, truth, model, dt = known_force_run()
    obs = DisturbanceObserver(model, GAIN, dt)
    est = []
    for q, qd, tau in samples:
        obs.update(q, qd, tau)
        est.append(obs.wrench(q))
    check_known_force(np.array(est), samples, truth, model, dt)
