"""The nonlinear disturbance observer: convergence, stability of the implicit update, checks."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.models import DeviceModel, SlideModel, SlideParams, UrdfModel
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_dob.core.tip_force import dls_transpose_solve
from haptic_sim.hand import HandParams
from haptic_sim.slide.device import SimulatedSlide
from haptic_sim.slide.plant import SlideDeviceParams
from support.paths import ROOT

OMNI_URDF = ROOT / "config" / "urdf" / "phantom_omni.urdf"


def constant_force_run(gain: float, force_n: float = 1.0, t_on: float = 0.1, drive=None):
    """Slide with an exact-model observer; a constant external force from ``t_on``.

    ``drive(t)`` is the actuator force (N); default a 0.3 N, 2 Hz sine.
    """
    drive = drive or (lambda t: 0.3 * math.sin(2 * math.pi * 2.0 * t))
    hand = HandParams(
        behaviour="push_hold",
        mass_kg=0.0,
        stiffness_n_per_m=0.0,
        damping_n_s_per_m=0.0,
        offset_m=0.0,
        amplitude_m=0.0,
        ramp_s=0.0,
        perturbation_n=force_n,
        perturbation_at_s=t_on,
        perturbation_s=1e3,
    )
    # a fine encoder: the test is about the observer, not about quantization noise
    dev = SimulatedSlide(
        SlideDeviceParams.matching(SlideParams(), encoder_resolution_m=1e-12), hand=hand
    )
    obs = DisturbanceObserver(dev.model, gain, dev.dt)
    tau = dev.model.mass_kg / gain
    n = round((t_on + 5 * tau) / dev.dt)
    t, d = np.arange(n) * dev.dt, np.empty(n)
    for k in range(n):
        s = dev.sample()
        d[k] = obs.update(s.q, s.qd, s.effort)[0]
        dev.apply([drive(k * dev.dt)])
    return t, d, tau


@pytest.mark.parametrize("gain", [2.0, 10.0, 41.6])
def test_error_decays_with_time_constant_m_over_c(gain: float) -> None:
    t, d, tau = constant_force_run(gain)
    err = 1.0 - d
    sel = (t > 0.1 + 0.003) & (t < 0.1 + 3 * tau)
    slope = np.polyfit(t[sel], np.log(err[sel]), 1)[0]
    measured = -1.0 / slope
    assert measured == pytest.approx(tau, rel=0.05)
    assert abs(err[-1]) < 0.02  # converged to the 1 N force


def test_estimate_stays_near_zero_without_external_force() -> None:
    """No external force, a varying actuator force that keeps the slide sliding: estimate ~ 0.

    (While the slide sticks, static friction balances the actuator and the model's
    ``Fc sgn(0) = 0`` makes the observer report it as an external force; this test keeps the
    slide moving to isolate the observer from that.)
    """
    t, d, _ = constant_force_run(
        10.0, t_on=3.0, drive=lambda t: 1.0 + 0.3 * math.sin(2 * math.pi * 2.0 * t)
    )
    before = (t > 0.05) & (t < 3.0)
    # what is left is the one-sample lag of the viscous term, b * a * T: a few mN
    assert np.max(np.abs(d[before])) < 0.01


class ConstantInertia(DeviceModel):
    """A 3-DOF model with constant inertia and no bias terms (a test double)."""

    def __init__(self, D: np.ndarray) -> None:
        self.D = D
        self.dof = D.shape[0]
        self.joint_names = tuple(f"j{i}" for i in range(self.dof))

    def _mass_matrix(self, q):
        return self.D.copy()

    def _coriolis_vector(self, q, qd):
        return np.zeros(self.dof)

    def _gravity(self, q):
        return np.zeros(self.dof)

    def _friction(self, qd):
        return np.zeros(self.dof)

    def _jacobian(self, q):
        return np.eye(3)[:, : self.dof]

    def _forward_kinematics(self, q):
        return np.zeros(3)


def simulate_constant_torque(model: ConstantInertia, d: np.ndarray, n: int, dt: float):
    """Exact (q, qd) samples for constant D, a constant disturbance and no actuation."""
    acc = np.linalg.solve(model.D, d)
    return [(acc * 0.5 * (k * dt) ** 2, acc * k * dt) for k in range(n)]


def forward_euler(model: ConstantInertia, c: float, dt: float, states, tau):
    """The explicit observer the implicit update replaces (for the regression test)."""
    z = -c * states[0][1]
    out = []
    Dinv = np.linalg.inv(model.D)
    with np.errstate(over="ignore", invalid="ignore"):
        for q, qd in states:
            z = z + dt * c * Dinv @ (-z + model._bias_effort(q, qd) - tau - c * qd)
            out.append(z + c * qd)
    return np.array(out)


def test_implicit_update_is_stable_where_forward_euler_diverges() -> None:
    # smallest eigenvalue 4e-4 kg m^2, the order of the Cavusoglu PHANToM's base inertia:
    # forward Euler needs T c / lambda_min < 2, here 5
    model = ConstantInertia(np.diag([4e-4, 8.5e-3, 6.3e-3]))
    c, dt = 2.0, 1e-3
    d_true = np.array([0.01, -0.02, 0.015])
    states = simulate_constant_torque(model, d_true, 2000, dt)
    obs = DisturbanceObserver(model, c, dt)
    est = np.array([obs.update(q, qd, np.zeros(3)) for q, qd in states])
    assert np.all(np.isfinite(est))
    np.testing.assert_allclose(est[-1], d_true, atol=1e-4)
    fe = forward_euler(model, c, dt, states, np.zeros(3))
    assert not np.all(np.abs(fe[-1]) < 1.0)  # diverged (overflowed to inf or nan)


def test_generic_update_equals_slide_fast_path() -> None:
    """Identity between the two algorithms: the matrix update with the matched gain."""
    slide = SlideModel()

    class GenericSlide(ConstantInertia):
        _has_friction = False  # friction inside the bias effort, at sample k as the slide's

        def _bias_effort(self, q, qd):
            return np.array([slide.friction_scalar(float(qd[0]))])

    fast = DisturbanceObserver(slide, 41.6, 1e-3)
    generic = DisturbanceObserver(GenericSlide(np.array([[0.416]])), fast.discrete_gain, 1e-3)
    rng = np.random.default_rng(3)
    for _ in range(500):
        q, qd, tau = rng.normal(size=3) * (0.01, 0.1, 1.0)
        a, b = fast.update([q], [qd], [tau]), generic.update([q], [qd], [tau])
        np.testing.assert_allclose(a, b, rtol=1e-11, atol=1e-12)


class ViscousMass(ConstantInertia):
    """One joint of mass ``m`` with viscous friction ``b`` (a test double)."""

    def __init__(self, m: float, b: float, separable: bool) -> None:
        super().__init__(np.array([[m]]))
        self.b = b
        self._has_friction = separable  # False: the friction is part of the bias, at sample k

    def _friction(self, qd):
        return self.b * qd


def test_a_multi_dof_update_takes_the_friction_over_the_period_from_both_ends() -> None:
    """A mass with viscous friction under a constant effort, sampled exactly (nothing
    external): its friction changes within each period. Taken from both ends of the period
    (trapezoid) the estimate stays at the rule's third-order error; held at sample k's value it
    is off by about ``b T a / 2``, a first-order error (measured: 1.5e-5 N against 4.6e-3 N)."""
    m, b, u, dt = 0.1, 2.0, 1.0, 1e-3
    lam = b / m
    states = [(u / b) * (1.0 - math.exp(-lam * k * dt)) for k in range(300)]

    def worst(separable: bool) -> float:
        obs = DisturbanceObserver(ViscousMass(m, b, separable), 10.0, dt)
        est = [obs.update([0.0], [v], [u])[0] for v in states]
        return float(np.max(np.abs(est[50:])))  # after the observer's start (10 ms)

    trapezoid, at_k = worst(True), worst(False)
    assert trapezoid < 1e-4, trapezoid
    assert at_k > 100.0 * trapezoid, (at_k, trapezoid)


def test_output_limit_clips_only_the_output() -> None:
    obs = DisturbanceObserver(SlideModel(), 41.6, 1e-3, limit=0.5)
    obs.update([0.0], [0.0], [0.0])
    for _ in range(200):
        d = obs.update([0.0], [0.0], [-2.0])  # held still against 2 N of actuator: d = 2 N
    assert d[0] == 0.5
    assert obs.estimate[0] == 0.5
    unclipped = DisturbanceObserver(SlideModel(), 41.6, 1e-3)
    unclipped.update([0.0], [0.0], [0.0])
    for _ in range(200):
        e = unclipped.update([0.0], [0.0], [-2.0])
    assert e[0] == pytest.approx(2.0, rel=1e-6)


def test_reset_rezeroes_and_reinitialises() -> None:
    obs = DisturbanceObserver(SlideModel(), 10.0, 1e-3)
    obs.update([0.0], [0.0], [0.0])
    obs.update([0.0], [0.0], [-1.0])
    assert obs.estimate[0] != 0.0
    obs.reset()
    assert obs.estimate[0] == 0.0 and not obs.initialised
    assert obs.update([0.0], [0.3], [1.0])[0] == 0.0
    assert obs.initialised


def test_wrench_of_the_slide_is_along_its_axis() -> None:
    obs = DisturbanceObserver(SlideModel(axis=(0.0, 1.0, 0.0)), 41.6, 1e-3)
    obs.update([0.0], [0.0], [0.0])
    for _ in range(100):
        obs.update([0.0], [0.0], [-1.0])
    f = obs.wrench([0.0])
    assert f[0] == 0.0 and f[2] == 0.0 and f[1] == pytest.approx(obs.estimate[0])


def test_damped_least_squares_is_exact_when_well_conditioned_and_bounded_when_singular() -> None:
    J = np.array([[0.2, 0.0, 0.1], [0.0, 0.15, 0.0], [0.05, 0.0, 0.2]])
    F = np.array([1.0, -2.0, 0.5])
    np.testing.assert_allclose(dls_transpose_solve(J, J.T @ F, 1e-2, 1e-2), F, atol=1e-12)
    J_sing = np.array([[0.2, 0.2, 0.0], [0.0, 0.0, 0.0], [0.0, 0.0, 0.1]])
    d = np.array([1.0, -1.0, 0.2])
    out = dls_transpose_solve(J_sing, d, 1e-2, 1e-2)
    assert np.all(np.isfinite(out)) and np.linalg.norm(out) < 1e3


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"gain": 0.0}, "gain"),
        ({"gain": -1.0}, "gain"),
        ({"gain": float("nan")}, "gain"),
        ({"dt": 0.0}, "dt"),
        ({"dt": float("inf")}, "dt"),
        ({"limit": 0.0}, "limit"),
        ({"limit": [1.0, 2.0]}, "limit"),
    ],
)
def test_observer_rejects_bad_settings(kwargs: dict, name: str) -> None:
    args = {"model": SlideModel(), "gain": 10.0, "dt": 1e-3} | kwargs
    with pytest.raises(ValueError, match=name):
        DisturbanceObserver(**args)


def test_observer_rejects_a_model_that_is_not_one() -> None:
    with pytest.raises(ValueError, match="model"):
        DisturbanceObserver("slide", 10.0, 1e-3)  # type: ignore[arg-type]  # the wrong type on purpose


@pytest.mark.parametrize(
    ("args", "name"),
    [
        (([float("nan")], [0.0], [0.0]), "q"),
        (([0.0], [np.inf], [0.0]), "qd"),
        (([0.0], [0.0], [0.0, 1.0]), "tau"),
        (([0.0, 1.0], [0.0], [0.0]), "q"),
    ],
)
def test_update_rejects_bad_samples(args, name: str) -> None:
    obs = DisturbanceObserver(SlideModel(), 10.0, 1e-3)
    with pytest.raises(ValueError, match=rf"^{name} "):
        obs.update(*args)
    generic = DisturbanceObserver(ConstantInertia(np.eye(1) * 0.4), 10.0, 1e-3)
    with pytest.raises(ValueError, match=rf"^{name} "):
        generic.update(*args)


@pytest.mark.parametrize("generic", [False, True])
def test_retune_keeps_the_estimate_and_takes_the_new_gain(generic: bool) -> None:
    """At constant velocity ``d_hat' = alpha d_hat + (1 - alpha)(h - tau)``: after a retune the
    next sample continues from the old estimate with the new gain's alpha."""
    model = ConstantInertia(np.array([[0.416]])) if generic else SlideModel(coulomb_n=0.0)
    obs = DisturbanceObserver(model, 10.0, 1e-3)
    obs.update([0.0], [0.2], [0.0])
    for _ in range(50):
        before = obs.update([0.0], [0.2], [-1.0])[0]
    obs.prepare()  # the next step's matrices made for the old gain: the retune makes them again
    obs.retune(40.0, limit=3.0)
    assert obs.gain == 40.0 and obs.limit.tolist() == [3.0]
    after = obs.update([0.0], [0.2], [-1.0])[0]
    h = 0.0 if generic else 1.272 * 0.2
    alpha = 0.416 / (0.416 + 1e-3 * 40.0) if generic else math.exp(-40.0 * 1e-3 / 0.416)
    assert after == pytest.approx(alpha * before + (1 - alpha) * (h + 1.0), rel=1e-12)
    with pytest.raises(ValueError, match="gain"):
        obs.retune(0.0)


def _omni_samples(n: int, seed: int) -> list[tuple[np.ndarray, np.ndarray, np.ndarray]]:
    """Random Touch-like samples (rad, rad/s, N m) about a posture inside its workspace."""
    rng = np.random.default_rng(seed)
    return [
        (
            np.array([0.0, 0.3, 0.2]) + 0.2 * rng.standard_normal(3),
            rng.standard_normal(3),
            0.05 * rng.standard_normal(3),
        )
        for _ in range(n)
    ]


def test_prepared_once_the_command_is_out_the_update_is_the_same_and_makes_no_dynamics() -> None:
    """``prepare()`` makes the next update's dynamics: an observer prepared after every update
    gives the very same estimates as one left to make them inside ``update``, and its updates
    (the command's path) make no dynamics at all."""
    model = UrdfModel(OMNI_URDF, "tip")
    lazy, prepared = DisturbanceObserver(model, 0.5, 2e-3), DisturbanceObserver(model, 0.5, 2e-3)
    made: list[str] = []
    dynamics = prepared._dynamics
    prepared._dynamics = lambda q, qd: (made.append("made"), dynamics(q, qd))[1]
    for q, qd, tau in _omni_samples(200, 5):
        a = lazy.update(q, qd, tau)
        b = prepared.update(q, qd, tau)
        assert not made  # the path made none
        prepared.prepare()
        assert made == ["made"]
        made.clear()
        assert np.array_equal(a, b)
    prepared.prepare()
    assert not made  # nothing pending: prepare once per sample


def test_the_step_matrices_give_the_implicit_update() -> None:
    """Identity between algorithms: ``z_{k+1} = P z_k + Q r`` against solving
    ``(D_k + T c I) z_{k+1} = D_k z_k + T c r`` at every sample (the module's equation)."""
    model = UrdfModel(OMNI_URDF, "tip")
    c, T = 0.5, 2e-3
    obs = DisturbanceObserver(model, c, T)
    z, D_prev, h_prev, f_prev = None, None, None, None
    for q, qd, tau in _omni_samples(300, 6):
        d = obs.update(q, qd, tau)
        D, h = model._mass_and_bias(q, qd)
        f = model._friction(qd)
        if z is None:
            z, ref = -c * qd, np.zeros(3)
        else:
            bias = h_prev + 0.5 * (f - f_prev)
            z = np.linalg.solve(
                D_prev + T * c * np.eye(3), D_prev @ z + T * c * (bias - tau - c * qd)
            )
            ref = z + c * qd
        D_prev, h_prev, f_prev = D, h, f
        np.testing.assert_allclose(d, ref, rtol=1e-9, atol=1e-12)
