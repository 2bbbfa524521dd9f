"""The Geomagic Touch / PHANToM Omni URDF: the PHANToM model's structure, the drivers' joints.

``config/urdf/phantom_omni.urdf`` closes the parallelogram with pinocchio's mimic joints and names
its joints as the community Touch drivers publish them (waist, shoulder, elbow; the elbow
relative to the upper arm). Read through ``UrdfModel``, it must be the PHANToM model of
``core/models/phantom.py`` (the open tree with ``q_t = S q``, theory.md section 5) with the same
links, to rounding: ``q_phantom = T q_touch + o``, ``T = [[1,0,0],[0,1,0],[0,1,1]]``,
``o = (-pi/2, 0, pi/2)`` (PhantomModel's yaw from +x, its crank angle absolute).
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest

from haptic_dob.core.models import PhantomModel, UrdfModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.models.phantom import LinkParams, PhantomParams
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.arm.device import SimulatedArm
from haptic_sim.device.batch import load_session
from haptic_sim.device.factory import build_device
from support.paths import ROOT

URDF = ROOT / "config" / "urdf" / "phantom_omni.urdf"
CONFIG = ROOT / "config" / "phantom_omni_sim.yaml"
JOINTS = ("waist", "shoulder", "elbow")
T = np.array([[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 1.0, 1.0]])
OFFSET = np.array([-math.pi / 2, 0.0, math.pi / 2])


def _floats(text: str | None) -> list[float]:
    return [float(v) for v in (text or "").split()]


def phantom_params_of_the_urdf() -> PhantomParams:
    """The URDF's numbers as PHANToM parameters, read from the XML itself (not through
    pinocchio): link lengths from the joints' origins, each link's mass, centre of mass along it
    and inertia (along it, about the joint axis x, across)."""
    root = ET.parse(URDF).getroot()
    joint = {j.get("name"): j for j in root.iter("joint")}
    link = {k.get("name"): k for k in root.iter("link")}

    def origin(name: str) -> list[float]:
        return _floats(joint[name].find("origin").get("xyz"))  # type: ignore[union-attr]

    def inertial(name: str, along: int) -> LinkParams:
        i = link[name].find("inertial")
        assert i is not None
        com = _floats(i.find("origin").get("xyz"))  # type: ignore[union-attr]
        mass = float(i.find("mass").get("value"))  # type: ignore[union-attr, arg-type]
        m = i.find("inertia")
        assert m is not None
        moments = [float(m.get(k)) for k in ("ixx", "iyy", "izz")]  # type: ignore[arg-type]
        across = 2 if along == 1 else 1
        # along -y (upper arm, rear link) or along z (forearm: -z, crank: +z)
        com_along = -com[1] if along == 1 else com[2]
        return LinkParams(mass, com_along, (moments[along], moments[0], moments[across]))

    torso = link["torso"].find("inertial").find("inertia")  # type: ignore[union-attr]
    forearm = inertial("lower_arm", 2)
    return PhantomParams(
        "touch",
        float(torso.get("izz")),  # type: ignore[union-attr, arg-type]
        -origin("elbow")[1],
        origin("parallel_rear")[2],
        -origin("tip_joint")[2],
        inertial("upper_arm", 1),
        inertial("crank", 2),
        inertial("rear_link", 1),
        LinkParams(forearm.mass_kg, -forearm.com_m, forearm.inertia_kg_m2),  # toward the tip
    )


def test_it_is_the_phantom_model_with_its_links() -> None:
    """D, C q', G, the tip and J of the URDF against PhantomModel on the same numbers."""
    touch = UrdfModel(URDF, "tip")
    phantom = PhantomModel(phantom_params_of_the_urdf())
    assert touch.joint_names == JOINTS  # the mimic joints follow elbow, no coordinates
    rng = np.random.default_rng(0)
    for _ in range(50):
        q, qd = rng.uniform(-1.0, 1.0, 3), rng.uniform(-3.0, 3.0, 3)
        qp, qdp = T @ q + OFFSET, T @ qd
        np.testing.assert_allclose(
            touch.mass_matrix(q), T.T @ phantom.mass_matrix(qp) @ T, atol=1e-15
        )
        np.testing.assert_allclose(touch.gravity(q), T.T @ phantom.gravity(qp), atol=1e-14)
        np.testing.assert_allclose(
            touch.coriolis_vector(q, qd), T.T @ phantom.coriolis_vector(qp, qdp), atol=1e-14
        )
        np.testing.assert_allclose(
            touch.forward_kinematics(q), phantom.forward_kinematics(qp), atol=1e-15
        )
        np.testing.assert_allclose(touch.jacobian(q), phantom.jacobian(qp) @ T, atol=1e-14)


def test_its_joints_turn_as_the_drivers_report_them() -> None:
    """Zero: the arm at the user (-y), level, the forearm hanging; positive waist turns it
    counter-clockwise from above, positive shoulder raises it, positive elbow swings the tip
    out toward the user."""
    touch = UrdfModel(URDF, "tip")
    np.testing.assert_allclose(touch.forward_kinematics([0, 0, 0]), [0.0, -0.134, -0.1325])
    x, y, _ = touch.forward_kinematics([0.1, 0.0, 0.0])
    assert x > 0.0 and y < 0.0
    assert touch.forward_kinematics([0.0, 0.1, 0.0])[2] > -0.1325 + 0.01
    assert touch.forward_kinematics([0.0, 0.0, 0.1])[1] < -0.134 - 0.01
    assert touch.effort_limits == (0.45, 0.45, 0.45)


def test_a_payload_adds_its_mass_and_weight_at_the_tip() -> None:
    """``urdf.payload_kg``: ``D + m J^T J`` and ``G + J^T (0, 0, m g)``, exactly."""
    plain = UrdfModel(URDF, "tip")
    loaded = build_model(
        {"model": "urdf", "urdf_path": str(URDF), "tip_frame": "tip", "urdf.payload_kg": 0.012}
    )
    q = np.array([0.2, 0.4, -0.3])
    J = plain.jacobian(q)
    np.testing.assert_allclose(
        loaded.mass_matrix(q), plain.mass_matrix(q) + 0.012 * J.T @ J, atol=1e-15
    )
    np.testing.assert_allclose(
        loaded.gravity(q), plain.gravity(q) + J.T @ [0.0, 0.0, 0.012 * 9.81], atol=1e-15
    )
    with pytest.raises(ValueError, match="payload_kg"):
        UrdfModel(URDF, "tip", payload_kg=-1.0)


def test_the_simulated_touch_keeps_a_truth_the_urdf_lacks() -> None:
    """config/phantom_omni_sim.yaml's device: its payload and friction, which the observer's
    model (the URDF as it is) lacks. Held still by its own gravity torques, the simulated Touch
    reads through the observer as a hand pushing down with the payload's weight."""
    nodes = load_session(CONFIG)
    device = build_device({**nodes["/**"], **nodes["device_node"], "hand.behaviour": "none"})
    assert isinstance(device, SimulatedArm)
    truth, model = device.model, build_model({**nodes["/**"], **nodes["observer_node"]})
    assert isinstance(truth, UrdfModel) and isinstance(model, UrdfModel)
    assert truth.payload_kg == 0.012 and model.payload_kg == 0.0
    assert truth.coulomb.tolist() == [0.02, 0.03, 0.02] and not model.coulomb.any()
    assert truth.joint_names == model.joint_names == JOINTS
    observer = DisturbanceObserver(model, 2.0, device.dt)
    for _ in range(600):
        s = device.sample()
        observer.update(s.q, s.qd, s.effort)
        device.apply(truth.gravity(device.q).tolist())
    np.testing.assert_allclose(device.q, nodes["device_node"]["arm.initial_position"], atol=1e-9)
    np.testing.assert_allclose(observer.wrench(device.q), [0.0, 0.0, -0.012 * 9.81], atol=2e-3)
