"""The Cartesian point-mass model: each axis the slide's model, and the loop's parts on it."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.core.control import ImpedanceController, ImpedanceLaw
from haptic_dob.core.models import PointMassModel, PointMassParams, SlideModel
from haptic_dob.core.models.factory import build_model, model_specs
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_dob.core.observers.momentum import MomentumObserver

MASS = (0.25, 0.22, 0.28)
VISCOUS = (1.0, 0.8, 1.2)
COULOMB = (0.06, 0.05, 0.08)


def model() -> PointMassModel:
    return PointMassModel(MASS, VISCOUS, COULOMB)


def test_each_axis_is_the_slides_model_along_its_axis() -> None:
    """D, C q', G, friction, J and the point: per axis the 1-DOF slide's, nothing coupled."""
    m = model()
    assert m.dof == 3 and m.joint_names == ("fd_x", "fd_y", "fd_z") and m.constant_jacobian
    rng = np.random.default_rng(0)
    for _ in range(20):
        q, qd = rng.uniform(-0.1, 0.1, 3), rng.uniform(-0.3, 0.3, 3)
        qd[rng.integers(3)] = 0.0  # a standing axis: no Coulomb friction in the model
        np.testing.assert_array_equal(m.mass_matrix(q), np.diag(MASS))
        np.testing.assert_array_equal(m.coriolis_vector(q, qd), np.zeros(3))
        np.testing.assert_array_equal(m.gravity(q), np.zeros(3))
        for i, axis in enumerate(np.eye(3)):
            slide = SlideModel(MASS[i], VISCOUS[i], COULOMB[i], axis=axis)
            assert m.friction(qd)[i] == pytest.approx(slide.friction_scalar(float(qd[i])))
            assert m.bias_effort(q, qd)[i] == pytest.approx(slide.friction_scalar(float(qd[i])))
            np.testing.assert_array_equal(m.jacobian(q)[:, i], slide.jacobian([q[i]])[:, 0])
        np.testing.assert_array_equal(m.forward_kinematics(q), q)


def test_the_settings_build_it_and_the_factory_names_it() -> None:
    values = {
        "model": "point_mass",
        "point_mass.mass_kg": [0.3, 0.31, 0.32],
        "point_mass.coulomb_n": [0.1, 0.1, 0.1],
        "point_mass.joint_names": ["x", "y", "z"],
    }
    m = build_model(values)
    assert isinstance(m, PointMassModel)
    assert m.mass_kg.tolist() == [0.3, 0.31, 0.32] and m.joint_names == ("x", "y", "z")
    assert m.viscous_n_s_per_m.tolist() == [0.0, 0.0, 0.0]
    specs = {s.name: s for s in model_specs()}
    assert "point_mass" in specs["model"].choices
    for name in ("mass_kg", "viscous_n_s_per_m", "coulomb_n", "joint_names"):
        spec = specs[f"point_mass.{name}"]
        assert spec.read_only and spec.length == 3, name
    assert specs["point_mass.mass_kg"].check([0.2, 0.0, 0.2]) is not None  # below 1e-3 kg
    with pytest.raises(ValueError, match=r"point_mass\.mass_kg must have 3 elements"):
        build_model({"model": "point_mass", "point_mass.mass_kg": [0.2, 0.2]})
    assert PointMassParams().model().mass_kg.tolist() == [0.2, 0.2, 0.2]


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"mass_kg": (0.2, 0.0, 0.2)}, "mass_kg"),
        ({"mass_kg": (0.2, 0.2)}, "mass_kg"),
        ({"viscous_n_s_per_m": -1.0}, "viscous_n_s_per_m"),
        ({"coulomb_n": (0.1, float("nan"), 0.1)}, "coulomb_n"),
        ({"joint_names": ("a", "a", "b")}, "joint_names"),
        ({"joint_names": ("a", "b")}, "joint_names"),
    ],
)
def test_it_refuses_bad_parameters(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        PointMassModel(**kwargs)


def _free_axes(force: np.ndarray, n: int, dt: float) -> tuple[np.ndarray, np.ndarray]:
    """Exact samples of frictionless masses from rest under ``force`` held over each period
    (zero-order hold): velocities ``(N, 3)`` and positions."""
    k = np.arange(n)[:, None]
    v = force / np.asarray(MASS) * dt * k
    x = 0.5 * force / np.asarray(MASS) * (dt * k) ** 2
    return v, x


def test_the_observer_recovers_a_known_force_on_each_axis_with_its_own_lag() -> None:
    """Frictionless axes under their actuators and an external force F the observer is not told
    of: its estimate is F through ``w_{k+1} = p w_k + (1 - p) F``, ``p = m / (m + T c)`` per axis
    (the implicit update's pole, theory.md section 3), to rounding."""
    dt, c, n = 1e-3, 30.0, 400
    obs_model = PointMassModel(MASS)
    observer = DisturbanceObserver(obs_model, c, dt)
    tau = np.array([0.5, -1.0, 0.2])
    f_ext = np.array([1.5, 0.7, -2.0])
    v, x = _free_axes(tau + f_ext, n, dt)
    est = np.array([observer.update(x[k], v[k], tau) for k in range(n)])
    p = np.asarray(MASS) / (np.asarray(MASS) + dt * c)
    want = f_ext * (1.0 - p ** np.arange(n)[:, None])
    np.testing.assert_allclose(est, want, atol=1e-12)
    # different masses, different lags: the heaviest axis is the slowest
    assert abs(est[20, 2] / f_ext[2]) < abs(est[20, 1] / f_ext[1])
    np.testing.assert_allclose(observer.wrench(x[-1]), est[-1])  # J = I: the wrench is d


def test_the_momentum_observer_recovers_it_too() -> None:
    """The generalized-momentum observer on the point mass: ``r`` follows F with 1 / K_I."""
    dt, gain, n = 1e-3, 50.0, 600
    observer = MomentumObserver(PointMassModel(MASS), gain, dt)
    tau, f_ext = np.array([0.2, 0.2, 0.2]), np.array([-1.0, 0.5, 2.0])
    v, x = _free_axes(tau + f_ext, n, dt)
    est = [observer.update(x[k], v[k], tau) for k in range(n)]
    np.testing.assert_allclose(est[-1], f_ext, rtol=1e-6)


def test_the_controller_commands_the_force_itself() -> None:
    """J = I: the joint efforts are the Cartesian command, no joint positions needed."""
    ctl = ImpedanceController(model(), ImpedanceLaw("DOB", kf=1.0, max_force_n=12.0))
    wall, est = (0.0, 0.0, 2.5), (0.0, 0.1, -2.0)
    assert ctl.command([0.0, 0.0, 0.0], wall, f_estimated=est) == pytest.approx([0.0, 0.1, 3.0])


class _Varying(PointMassModel):
    """The same point mass, declared as if its D could change with q."""

    constant_mass_matrix = False


def test_the_observer_makes_its_step_once_and_estimates_exactly_the_same(monkeypatch) -> None:
    """Its D is constant: the step's inverse is made once per gain, not every sample, and the
    estimates equal those of an observer that remakes it every sample, bit for bit."""
    params = ([0.2, 0.21, 0.22], [1.0, 1.1, 1.2], [0.1, 0.1, 0.1])
    rng = np.random.default_rng(0)
    samples = rng.normal(size=(200, 3, 3)) * (1e-3, 1e-2, 1.0)
    inverses = []
    real_inv = np.linalg.inv
    monkeypatch.setattr(np.linalg, "inv", lambda a: inverses.append(1) or real_inv(a))
    estimates = []
    for model in (PointMassModel(*params), _Varying(*params)):
        inverses.clear()
        obs = DisturbanceObserver(model, 30.0, 1e-3, 4.0)
        out = []
        for k, (q, qd, tau) in enumerate(samples):
            if k == 100:
                obs.retune(20.0)  # a new gain: a new step
            out.append(obs.update(q, qd, tau))
            obs.prepare()
        estimates.append(np.array(out))
        made = len(inverses)  # one per gain, or one per sample (and the retune's)
        assert made == 2 if model.constant_mass_matrix else made >= len(samples), made
    assert np.array_equal(estimates[0], estimates[1])
