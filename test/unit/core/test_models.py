"""The device-model interface and the slide model."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.core.models import SlideModel, SlideParams


def test_slide_defaults_are_the_thesis_identification() -> None:
    m = SlideModel()
    assert (m.mass_kg, m.viscous_n_s_per_m, m.coulomb_n) == (0.416, 1.272, 0.24)
    assert m.dof == 1 and m.joint_names == ("slide",)
    assert SlideParams().model().mass_kg == 0.416


def test_slide_terms_and_kinematics() -> None:
    m = SlideModel(axis=(0.0, 0.0, 2.0))
    assert m.mass_matrix([0.3]).tolist() == [[0.416]]
    assert m.coriolis_vector([0.3], [1.0]).tolist() == [0.0]
    assert m.gravity([0.3]).tolist() == [0.0]
    assert m.friction([0.5]) == pytest.approx([1.272 * 0.5 + 0.24])
    assert m.friction([-0.5]) == pytest.approx([-1.272 * 0.5 - 0.24])
    assert m.friction([0.0]).tolist() == [0.0]
    np.testing.assert_allclose(m.jacobian([0.3]), [[0.0], [0.0], [1.0]])
    np.testing.assert_allclose(m.forward_kinematics([0.3]), [0.0, 0.0, 0.3])
    np.testing.assert_allclose(m.bias_effort([0.0], [0.5]), m.friction([0.5]))


def test_jacobian_is_derivative_of_forward_kinematics() -> None:
    m = SlideModel(axis=(1.0, 2.0, -1.0))
    q, h = np.array([0.02]), 1e-7
    fd = (m.forward_kinematics(q + h) - m.forward_kinematics(q - h)) / (2 * h)
    np.testing.assert_allclose(m.jacobian(q)[:, 0], fd, atol=1e-9)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"mass_kg": 0.0}, "mass_kg"),
        ({"mass_kg": float("nan")}, "mass_kg"),
        ({"viscous_n_s_per_m": -1.0}, "viscous_n_s_per_m"),
        ({"coulomb_n": float("inf")}, "coulomb_n"),
        ({"axis": (0.0, 0.0, 0.0)}, "axis"),
        ({"axis": (1.0, 0.0)}, "axis"),
    ],
)
def test_slide_rejects_bad_parameters(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        SlideModel(**kwargs)


@pytest.mark.parametrize(
    ("call", "name"),
    [
        (lambda m: m.mass_matrix([0.1, 0.2]), "q"),
        (lambda m: m.forward_kinematics([float("nan")]), "q"),
        (lambda m: m.coriolis_vector([0.0], [np.inf]), "qd"),
        (lambda m: m.friction([[1.0]]), "qd"),
        (lambda m: m.jacobian("x"), "q"),
    ],
)
def test_slide_rejects_bad_states(call, name: str) -> None:
    with pytest.raises(ValueError, match=rf"^{name} "):
        call(SlideModel())
