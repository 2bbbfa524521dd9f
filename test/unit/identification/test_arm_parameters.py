"""The pieces of an arm's identification: the regressor, the base set, the consistent
parametrisation, the URDF written back and read again, armature in the model."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_inertia import bodies, body_parameters
from haptic_dob.core.models.factory import build_model
from haptic_dob.identification import arm_parameters as ap
from haptic_dob.identification.arm_consistent import Link, pseudo_inertia
from haptic_dob.identification.arm_consistent import body_parameters as link_parameters
from haptic_dob.identification.arm_urdf import (
    JointDynamics,
    LinkInertial,
    link_inertials,
    rewrite_urdf,
)

ROOT = Path(__file__).resolve().parents[3]
ARM7 = ROOT / "config" / "urdf" / "arm7.urdf"
ARM6 = ROOT / "config" / "urdf" / "arm6_gripper.urdf"
OMNI = ROOT / "config" / "urdf" / "phantom_omni.urdf"
ARMATURE = [0.1, 0.12, 0.07, 0.08, 0.06, 0.02, 0.03]


def states(dof: int, n: int, seed: int = 1):
    rng = np.random.default_rng(seed)
    return rng.uniform(-2, 2, (n, dof)), rng.uniform(-1, 1, (n, dof)), rng.uniform(-3, 3, (n, dof))


def test_the_regressor_times_the_parameters_is_the_models_inverse_dynamics() -> None:
    """Rigid body (pinocchio's), armature, viscous and Coulomb friction (a sign here): ``W
    theta`` is the model's RNEA with all of them, to rounding."""
    viscous, coulomb = np.linspace(0.1, 0.7, 7), np.linspace(0.2, 1.4, 7)
    model = UrdfModel(ARM7, "tool", viscous=viscous, coulomb=coulomb, armature=ARMATURE)
    x, v, a = states(7, 20)
    W = ap.regressor(model, x, v, a, np.sign(v))
    theta = np.concatenate([body_parameters(model).ravel(), ARMATURE, viscous, coulomb])
    expected = np.array([model.inverse_dynamics(*s) for s in zip(x, v, a, strict=True)])
    np.testing.assert_allclose(W @ theta, expected.ravel(), atol=1e-10)
    assert ap.layout_of(model).names[:2] == ("link1.m", "link1.mx")
    assert ap.layout_of(model).names[-1] == "joint7.coulomb"


def test_a_parallelogram_s_mimic_joints_have_a_regressor() -> None:
    """The Touch's parallelogram (two mimic joints following the elbow, which pinocchio's
    regressor refuses): its five bodies' columns by RNEA's differences, ``W theta`` its RNEA with
    a payload and friction, and the model's own inertias put back."""
    model = UrdfModel(OMNI, "tip", viscous=0.01, coulomb=0.02, payload_kg=0.012)
    before = body_parameters(model).copy()
    x, v, a = states(3, 20, seed=4)
    W = ap.regressor(model, x, v, a, np.sign(v))
    links = [b.link for b in bodies(model)]
    assert links == ["torso", "upper_arm", "lower_arm", "crank", "rear_link"]
    theta = np.concatenate([before.ravel(), np.zeros(3), np.full(3, 0.01), np.full(3, 0.02)])
    expected = np.array([model.inverse_dynamics(*s) for s in zip(x, v, a, strict=True)])
    np.testing.assert_allclose(W @ theta, expected.ravel(), atol=1e-12)
    np.testing.assert_array_equal(body_parameters(model), before)


def test_the_base_set_carries_every_standard_parameter() -> None:
    """``W theta = W_b beta`` for any theta over new states; on arm7 the first body (turning
    about the vertical) shows only its inertia about the axis, which its joint's armature joins."""
    model = UrdfModel(ARM7, "tool")
    lay = ap.layout_of(model)
    bs = ap.base_set(ap.regressor(model, *ap.reference_states(model, 300)))
    assert len(bs.base) + len(bs.dependent) == lay.size
    dependent = {lay.names[i] for i in bs.dependent}
    assert {"link1.m", "link1.mx", "link1.Ixx", "joint1.armature"} <= dependent
    assert not dependent & {"link1.Izz", "link7.Ixy", "joint7.armature", "joint3.coulomb"}
    W = ap.regressor(model, *ap.reference_states(model, 50, seed=9))
    theta = np.random.default_rng(2).normal(size=lay.size)
    np.testing.assert_allclose(W[:, bs.base] @ bs.beta(theta), W @ theta, rtol=1e-9, atol=1e-9)


def test_a_record_that_moves_one_joint_does_not_see_the_others() -> None:
    model = UrdfModel(ARM7, "tool")
    ref = ap.regressor(model, *ap.reference_states(model, 300))
    bs = ap.base_set(ref)
    x, v, a = states(7, 200)
    x[:, 1:], v[:, 1:], a[:, 1:] = 0.3, 0.0, 0.0
    data = ap.regressor(model, x, v, a, np.sign(v))[:, bs.base]
    gram = ref[:, bs.base].T @ ref[:, bs.base] / 300
    seen = ap.visibility(data.T @ data / 200, gram)
    names = bs.names(ap.layout_of(model))
    unseen = ap.unseen_names(names, seen, 1e-4)
    assert "link3.Ixx" in unseen and "joint5.viscous" in unseen
    assert "joint1.viscous" not in unseen
    rich = ap.regressor(model, *ap.reference_states(model, 200, seed=4))[:, bs.base]
    assert np.min(ap.visibility(rich.T @ rich / 200, gram)) > 0.3


def test_every_value_of_the_parametrisation_is_physically_consistent() -> None:
    """Mass > 0, centre of mass in the box, pseudo-inertia positive definite, at random
    variables far from CAD; the CAD values at the start."""
    sigma = np.diag([0.01, 0.02, 0.004])
    link = Link(2.0, np.array([0.0, 0.01, 0.1]), sigma, np.array([-0.1, -0.1, -0.05]),
                np.array([0.1, 0.1, 0.3]), np.zeros(10))  # fmt: skip
    m, c, s = link.values(link.start())
    assert m == pytest.approx(2.0) and np.allclose(c, link.com) and np.allclose(s, sigma)
    rng = np.random.default_rng(3)
    for x in rng.normal(0.0, 3.0, (200, 10)):
        m, c, s = link.values(x)
        assert m > 0.0 and np.all(c >= link.lo) and np.all(c <= link.hi)
        assert np.linalg.eigvalsh(pseudo_inertia(m, c, s))[0] > 0.0
        inertia = np.trace(s) * np.eye(3) - s
        p = np.linalg.eigvalsh(inertia)
        assert p[0] + p[1] >= p[2] * (1 - 1e-12)  # the triangle inequality
    assert link_parameters(2.0, np.zeros(3), sigma)[0] == 2.0


def test_the_urdf_written_back_loads_with_its_values(tmp_path) -> None:
    """New inertials (an rpy in the CAD's inertial is applied when read), friction, armature
    and the Coulomb turn: written, the model reads each of them back; comments survive; a
    ``<transmission>`` naming the joints (as ros2_control descriptions hold) is left alone."""
    transmissions = "".join(
        f'<transmission name="t{i}"><joint name="joint{i}"><hardwareInterface>x</hardwareInterface>'
        f"</joint></transmission>"
        for i in range(1, 8)
    )
    xml = (
        ARM7.read_text()
        .replace(
            '<origin xyz="0 0 0.105" rpy="0 0 0"/>\n      <mass value="4"/>',
            '<origin xyz="0 0 0.105" rpy="0.3 0.2 0.1"/>\n      <mass value="4"/>',
        )
        .replace("</robot>", transmissions + "</robot>")
    )
    cad = link_inertials(xml)
    assert not np.allclose(cad["link2"].inertia, np.diag(np.diag(cad["link2"].inertia)))
    new = LinkInertial(3.5, np.array([0.01, -0.02, 0.12]), np.diag([0.02, 0.03, 0.01]))
    dyn = {
        f"joint{i + 1}": JointDynamics(0.1 * i, 0.2 * i, 0.003 * i, ARMATURE[i]) for i in range(7)
    }
    out = rewrite_urdf(xml, {"link3": new}, dyn, "a test -- of the note")
    assert "Links are uniform rods" in out and "a test - - of the note" in out
    path = tmp_path / "arm.urdf"
    path.write_text(out)
    loaded = build_model({"model": "urdf", "urdf_path": str(path), "tip_frame": "tool"})
    assert isinstance(loaded, UrdfModel)
    np.testing.assert_allclose(loaded.armature, ARMATURE)
    np.testing.assert_allclose(loaded.viscous, [0.1 * i for i in range(7)])
    np.testing.assert_allclose(loaded.coulomb_speed, [0.003 * i for i in range(7)])
    np.testing.assert_allclose(link_inertials(out)["link3"].inertia, new.inertia)
    body3 = body_parameters(loaded)[2]
    np.testing.assert_allclose(
        body3,
        link_parameters(3.5, new.com, 0.5 * np.trace(new.inertia) * np.eye(3) - new.inertia),
        atol=1e-12,
    )
    np.testing.assert_allclose(
        body_parameters(UrdfModel(xml, "tool"))[1], body_parameters(loaded)[1], atol=1e-12
    )
    override = build_model(
        {"model": "urdf", "urdf_path": str(path), "tip_frame": "tool", "urdf.armature_kg_m2": [0.5]}
    )
    np.testing.assert_allclose(override.armature, 0.5)


def test_armature_adds_to_the_inertia_diagonal_and_a_bad_value_is_named() -> None:
    plain, geared = UrdfModel(ARM6, "tcp"), UrdfModel(ARM6, "tcp", armature=0.2)
    q = np.array([0.4, 0.6, 0.9, -0.5, 0.7, 0.3])
    np.testing.assert_allclose(
        geared.mass_matrix(q) - plain.mass_matrix(q), 0.2 * np.eye(6), atol=1e-12
    )
    bad = (
        ARM7.read_text()
        .replace(
            '<joint name="joint2" type="revolute">',
            '<joint name="joint2" type="revolute"><haptic_dob:dynamics armature="-1"/>',
        )
        .replace(
            '<robot name="haptic_dob_arm7">',
            '<robot name="haptic_dob_arm7" xmlns:haptic_dob="urn:haptic-dob:urdf">',
        )
    )
    with pytest.raises(ValueError, match="joint joint2: armature must be a number >= 0"):
        UrdfModel(bad, "tool")


def test_the_bodies_are_the_joints_child_links_with_what_is_fixed_to_them() -> None:
    model = UrdfModel(ARM7, "tool")
    found = bodies(model)
    assert [b.link for b in found] == [f"link{i}" for i in range(1, 8)]
    assert [name for name, _ in found[-1].links] == ["link7", "tool"]
    np.testing.assert_allclose(found[-1].points.max(axis=0), [0.0, 0.0, 0.045])
