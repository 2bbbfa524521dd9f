"""Real arms' URDFs: continuous, mimic and fixed joints, grippers, meshes; a known tip force.

``config/urdf/arm6_gripper.urdf`` (ours, always run) holds what real descriptions hold. Third-party
arms come from the ``example-robot-data`` package (``support.published_arms``), skipped with a
reason when it is absent. The known-force checks run the arm in ``armsim.AbaArm``, a simulator
of the tests' own (articulated-body algorithm, a spatial force on the tip's body, integration on
pinocchio's configuration), not the observer's model run backwards.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from support.armsim import AbaArm
from support.published_arms import ARMS, ROBOTS, SKIP_REASON

ROOT = Path(__file__).resolve().parents[3]
ARM6 = ROOT / "config" / "urdf" / "arm6_gripper.urdf"
ARM6_START = [0.4, 0.6, 0.9, -0.5, 0.7, 0.3]
CONTINUOUS = ("joint1", "joint4", "joint6")


def random_states(dof: int, n: int = 20, seed: int = 3):
    """Joint positions (beyond +-pi too) and velocities."""
    rng = np.random.default_rng(seed)
    return zip(rng.uniform(-5.0, 5.0, (n, dof)), rng.uniform(-2.0, 2.0, (n, dof)), strict=True)


def test_a_continuous_joint_is_its_angle() -> None:
    """The same arm with its continuous joints written as revolute ones: every term equal."""
    xml = ARM6.read_text()
    revolute = xml
    for name in CONTINUOUS:
        revolute = revolute.replace(
            f'name="{name}" type="continuous"', f'name="{name}" type="revolute"'
        )
    revolute = revolute.replace("<limit effort=", '<limit lower="-1e9" upper="1e9" effort=')
    cont, rev = UrdfModel(xml, "tcp"), UrdfModel(revolute, "tcp")
    assert cont.joint_names == rev.joint_names == tuple(f"joint{i}" for i in range(1, 7))
    assert cont._model.nq == 9 and rev._model.nq == 6  # (cos, sin) for each continuous joint
    for q, qd in random_states(6):
        np.testing.assert_allclose(cont.mass_matrix(q), rev.mass_matrix(q), atol=1e-12)
        np.testing.assert_allclose(cont.bias_effort(q, qd), rev.bias_effort(q, qd), atol=1e-11)
        np.testing.assert_allclose(cont.jacobian(q), rev.jacobian(q), atol=1e-12)
        np.testing.assert_allclose(
            cont.forward_kinematics(q), rev.forward_kinematics(q), atol=1e-12
        )
        np.testing.assert_allclose(
            cont.forward_kinematics(q + 2 * math.pi), cont.forward_kinematics(q), atol=1e-12
        )


def test_a_mimic_finger_follows_its_master() -> None:
    """Tip on the mimicking finger: one coordinate for both fingers, the chain rule's terms."""
    xml = ARM6.read_text()
    mimic = UrdfModel(xml, "finger_right_tip")
    assert mimic.joint_names[-1] == "finger_left_joint"  # the master, not the mimic
    free_xml = xml.replace('<mimic joint="finger_left_joint" multiplier="1" offset="0"/>', "")
    names = [*mimic.joint_names, "finger_right_joint"]
    free = UrdfModel(free_xml, "finger_right_tip", names)
    S = np.zeros((8, 7))
    S[:7, :7] = np.eye(7)
    S[7, 6] = 1.0  # the right finger moves as the left one
    for q, qd in random_states(7):
        qf, qdf = S @ q, S @ qd
        np.testing.assert_allclose(mimic.mass_matrix(q), S.T @ free.mass_matrix(qf) @ S, atol=1e-12)
        np.testing.assert_allclose(
            mimic.bias_effort(q, qd), S.T @ free.bias_effort(qf, qdf), atol=1e-11
        )
        np.testing.assert_allclose(mimic.jacobian(q), free.jacobian(qf) @ S, atol=1e-12)


def test_fixed_joints_and_the_gripper_are_locked_and_meshes_never_read(tmp_path: Path) -> None:
    """The chain to the tool point has the six arm joints; the gripper's mass is carried; the
    package:// and relative mesh paths (none exist) are never opened, from a file or as text."""
    copy = tmp_path / "arm.urdf"
    copy.write_text(ARM6.read_text())
    for source in (copy, ARM6.read_text()):
        model = UrdfModel(source, "tcp")
        assert model.joint_names == tuple(f"joint{i}" for i in range(1, 7))
        assert model.effort_limits == (60.0, 60.0, 30.0, 12.0, 12.0, 12.0)
        np.testing.assert_allclose(model.forward_kinematics(np.zeros(6)), [0, 0, 1.38], atol=1e-12)
        assert pin.computeTotalMass(model._model) == pytest.approx(11.1)  # arm, hand, fingers


def test_joint_friction_comes_from_the_urdf_and_can_be_given() -> None:
    """``<dynamics damping friction>`` (arm6: 0.05 N m s/rad, 0.2 N m) is the model's joint
    friction ``b q' + Fc sgn(q')`` unless given; the rigid-body terms stay as they are."""
    urdf, bare = UrdfModel(ARM6, "tcp"), UrdfModel(ARM6, "tcp", viscous=0.0, coulomb=0.0)
    assert urdf.viscous.tolist() == [0.05] * 6 and urdf.coulomb.tolist() == [0.2] * 6
    for q, qd in random_states(6):
        np.testing.assert_allclose(
            urdf.bias_effort(q, qd) - bare.bias_effort(q, qd),
            0.05 * qd + 0.2 * np.sign(qd),
            atol=1e-12,
        )
        np.testing.assert_allclose(urdf.friction(qd), 0.05 * qd + 0.2 * np.sign(qd))
    given = build_model(
        {
            "model": "urdf",
            "urdf_path": str(ARM6),
            "tip_frame": "tcp",
            "urdf.viscous_n_m_s_per_rad": [0.1, 0.1, 0.1, 0.2, 0.2, 0.2],
            "urdf.coulomb_n_m": [0.0],
        }
    )
    assert given.viscous.tolist() == [0.1] * 3 + [0.2] * 3 and not given.coulomb.any()
    with pytest.raises(ValueError, match=r"coulomb must have shape \(6,\)"):
        build_model(
            {
                "model": "urdf",
                "urdf_path": str(ARM6),
                "tip_frame": "tcp",
                "urdf.coulomb_n_m": [0.1, 0.2],
            }
        )


def with_joint(kind: str) -> str:
    """arm6 with a ``kind`` joint between the world and its base."""
    return ARM6.read_text().replace(
        'name="world_joint" type="fixed"', f'name="world_joint" type="{kind}"'
    )


@pytest.mark.parametrize(("kind", "dof"), [("floating", 6), ("planar", 3)])
def test_a_multi_dof_joint_is_refused_in_the_chain_by_name_and_locked_when_left_out(
    kind, dof
) -> None:
    with pytest.raises(ValueError) as err:
        UrdfModel(with_joint(kind), "tcp")
    msg = str(err.value)
    assert f"joint world_joint is a {kind} joint ({dof} DOF)" in msg and "\n" not in msg
    arm = UrdfModel(with_joint(kind), "tcp", [f"joint{i}" for i in range(1, 7)])
    np.testing.assert_allclose(arm.forward_kinematics(np.zeros(6)), [0, 0, 1.38], atol=1e-12)
    with pytest.raises(ValueError, match=r"world_joint is a .* joint .*leave it out"):
        UrdfModel(with_joint(kind), "tcp", ["world_joint", "joint1"])


def test_a_mimic_joint_named_as_a_coordinate_is_refused_naming_its_master() -> None:
    with pytest.raises(ValueError, match=r"finger_right_joint \(it follows finger_left_joint\)"):
        UrdfModel(ARM6, "finger_right_tip", ["joint1", "finger_right_joint"])


# --- a known tip force, held and moving ---------------------------------------------------------
FORCE = np.array([2.0, -1.0, 3.0])  # N, from T_ON
T_ON = 0.2  # s
SECONDS = 1.0
TAU_OBS = 0.01  # s: the observer's slowest time constant at the start posture


def known_force_error(xml: str, tip: str, start, swing_rad: float) -> float:
    """Largest tip-force error (N) once the observer settled, the arm held or swinging.

    PD on the joints (5 Hz, damping 0.7 on the diagonal of D) plus the model's gravity around
    ``start`` (+ ``swing_rad`` at 0.5 Hz on revolute and continuous joints); the observer's gain
    puts its slowest time constant at ``TAU_OBS``. Before the force, the estimate must stay
    within 1 % of ``|FORCE|`` too.
    """
    model = UrdfModel(xml, tip, viscous=0.0, coulomb=0.0)  # the simulator has no joint friction
    start = np.asarray(start, dtype=np.float64)
    sim = AbaArm(xml, tip, model.joint_names, start, FORCE, T_ON)
    D0 = model.mass_matrix(start)
    obs = DisturbanceObserver(model, float(np.linalg.eigvalsh(D0)[-1]) / TAU_OBS, sim.dt)
    w = 2 * math.pi * 5.0
    kp, kd = w * w * np.diag(D0), 2 * 0.7 * w * np.diag(D0)
    prismatic = np.array(
        [
            model._model.joints[model._model.getJointId(n)].shortname().startswith("JointModelP")
            for n in model.joint_names
        ]
    )
    amplitude = np.where(prismatic, 0.0, swing_rad)
    errors_before, errors_after = [0.0], [0.0]
    tau = None
    for k in range(int(SECONDS / sim.dt)):
        t = k * sim.dt
        q, qd = sim.angles(), sim.velocities()
        if tau is not None:
            obs.update(q, qd, tau)
            err = float(np.linalg.norm(obs.wrench(q) - sim.tip_force(t)))
            if 0.05 <= t < T_ON:
                errors_before.append(err)
            elif t >= T_ON + 10 * TAU_OBS:
                errors_after.append(err)
        ref = start + amplitude * math.sin(2 * math.pi * 0.5 * t)
        tau = model.gravity(q) + kp * (ref - q) - kd * qd
        sim.step(tau)
    assert max(errors_before) < 0.01 * np.linalg.norm(FORCE), max(errors_before)
    return max(errors_after)


@pytest.mark.parametrize("tip", ["tcp", "finger_right_tip"])
@pytest.mark.parametrize("swing_rad", [0.0, 0.15], ids=["held", "moving"])
def test_observer_recovers_a_known_tip_force_on_arm6(tip: str, swing_rad: float) -> None:
    start = ARM6_START + ([0.02] if tip != "tcp" else [])
    err = known_force_error(ARM6.read_text(), tip, start, swing_rad)
    assert err < 0.02 * np.linalg.norm(FORCE), err


@pytest.mark.skipif(ROBOTS is None, reason=SKIP_REASON)
@pytest.mark.parametrize("arm", sorted(ARMS))
@pytest.mark.parametrize("swing_rad", [0.0, 0.15], ids=["held", "moving"])
def test_observer_recovers_a_known_tip_force_on_third_party_arms(
    arm: str, swing_rad: float
) -> None:
    assert ROBOTS is not None
    path, tip, start = ARMS[arm]
    err = known_force_error((ROBOTS / path).read_text(), tip, start, swing_rad)
    assert err < 0.02 * np.linalg.norm(FORCE), err


def test_the_simulated_arm_runs_a_mimic_gripper_with_urdf_friction_and_a_tip_force() -> None:
    """The device's simulator on arm6's right finger (a mimic joint in the chain, the URDF's
    Coulomb friction smoothed, a tip force): it integrates, holds still under gravity
    compensation and PD, and its potential energy is the free model's."""
    from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm

    model = UrdfModel(ARM6, "finger_right_tip")
    start = [*ARM6_START, 0.02]
    dev = SimulatedArm(
        model,
        ArmDeviceParams(
            initial_position=start,
            external_force_n=(0.0, 0.0, -1.0),
            external_force_at_s=0.1,
            encoder_resolution_rad=0.0,
        ),
    )
    assert dev._coulomb_eps.min() >= 1e-3
    D0 = model.mass_matrix(start)
    for _ in range(500):
        s = dev.sample()
        q, qd = np.array(s.q), np.array(s.qd)
        dev.apply((model.gravity(q) + 400.0 * np.diag(D0) * (start - q) - 5.0 * qd).tolist())
    assert np.all(np.isfinite(dev.q)) and np.max(np.abs(dev.q - start)) < 0.05
    free_xml = ARM6.read_text().replace(
        '<mimic joint="finger_left_joint" multiplier="1" offset="0"/>', ""
    )
    free = UrdfModel(free_xml, "finger_right_tip", [*model.joint_names, "finger_right_joint"])
    q = np.array(start)
    assert model.potential_energy(q) == pytest.approx(free.potential_energy(np.append(q, q[-1])))
