"""The PHANToM 1.5 model: pinocchio against closed forms written here, SPD inertia, energy.

The closed forms below are written from theory.md section 5 (appendix B, corrected) and from
Cavusoglu, Feygin and Tendick (2002) (their y-up frame, ``theta3 = phi3 - pi/2``, with the
corrected sign of C32), independently of the pinocchio construction in ``haptic_dob.core.models``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.models import DeviceModel, PhantomModel
from haptic_dob.core.models.phantom import HOME
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm

G0 = 9.81

# --- thesis Table B.1 -----------------------------------------------------------------------
APP_B = {
    "l1": 0.178,
    "l2": 0.089,
    "le4": 0.221,
    "Ib": 0.0915,
    "m": (0.047, 0.020, 0.034, 0.228),
    "lc": (0.112, 0.0445, 0.0785, 0.127),
    "I": (2.83e-4, 3.17e-5, 1.81e-4, 2.29e-3),
}


def appendix_b(q, qd, p=APP_B):
    """D, C (Christoffel), G, p and J of theory.md section 5."""
    m1, m2, m3, m4 = p["m"]
    lc1, lc2, lc3, lc4 = p["lc"]
    I1, I2, I3, I4 = p["I"]
    l1, l2, le4 = p["l1"], p["l2"], p["le4"]
    _, p2, p3 = q
    c2, s2, c3, s3 = math.cos(p2), math.sin(p2), math.cos(p3), math.sin(p3)
    D22 = I1 + I3 + m1 * lc1**2 + m3 * lc3**2 + m4 * l1**2
    D33 = I2 + I4 + m2 * lc2**2 + m3 * l2**2 + m4 * lc4**2
    hs = m4 * lc4 * l1 - m3 * lc3 * l2
    D = np.array(
        [
            [p["Ib"] + D22 * c2**2 + D33 * c3**2 - 2 * hs * c2 * c3, 0.0, 0.0],
            [0.0, D22, -hs * math.cos(p2 - p3)],
            [0.0, -hs * math.cos(p2 - p3), D33],
        ]
    )
    G = np.array(
        [0.0, G0 * (m1 * lc1 + m3 * lc3 + m4 * l1) * c2, G0 * (m2 * lc2 + m3 * l2 - m4 * lc4) * c3]
    )
    d2 = -D22 * math.sin(2 * p2) + 2 * hs * s2 * c3
    d3 = -D33 * math.sin(2 * p3) + 2 * hs * c2 * s3
    a, b, c = qd
    C = np.array(
        [
            [(d2 * b + d3 * c) / 2, d2 * a / 2, d3 * a / 2],
            [-d2 * a / 2, 0.0, hs * math.sin(p3 - p2) * c],
            [-d3 * a / 2, -hs * math.sin(p3 - p2) * b, 0.0],
        ]
    )
    return D, C, G, *kinematics(q, l1, le4)


def kinematics(q, l1, le4):
    """End-effector point and linear Jacobian of theory.md section 5 (z up)."""
    p1, p2, p3 = q
    c1, s1 = math.cos(p1), math.sin(p1)
    c2, s2, c3, s3 = math.cos(p2), math.sin(p2), math.cos(p3), math.sin(p3)
    r = l1 * c2 - le4 * c3
    pos = np.array([r * c1, r * s1, l1 * s2 - le4 * s3])
    J = np.array(
        [
            [-r * s1, -l1 * s2 * c1, le4 * s3 * c1],
            [r * c1, -l1 * s2 * s1, le4 * s3 * s1],
            [0.0, l1 * c2, -le4 * c3],
        ]
    )
    return pos, J


def appendix_b_potential(q, p=APP_B):
    """Gravitational potential energy (J) up to a constant."""
    m1, m2, m3, m4 = p["m"]
    lc1, lc2, lc3, lc4 = p["lc"]
    a = G0 * (m1 * lc1 + m3 * lc3 + m4 * p["l1"])
    b = G0 * (m2 * lc2 + m3 * p["l2"] - m4 * lc4)
    return a * math.sin(q[1]) + b * math.sin(q[2])


# --- Cavusoglu, Feygin and Tendick (2002) ------------------------------------------------------
E4 = 1e-4
CAV = {
    "l1": 0.215,
    "l2": 0.170,
    "l3": 0.0325,
    "l5": -0.0368,
    "l6": 0.0527,
    "ma": 0.0202,
    "mc": 0.0249,
    "mbe": 0.2359,
    "mdf": 0.1906,
    "Ia": (0.4864 * E4, 0.001843 * E4, 0.4864 * E4),
    "Ic": (0.959 * E4, 0.959 * E4, 0.0051 * E4),
    "Ibe": (11.09 * E4, 10.06 * E4, 0.591 * E4),
    "Idf": (7.11 * E4, 0.629 * E4, 6.246 * E4),
    "Ibase": 11.87 * E4,
}


def cavusoglu(th, thd, p=CAV):
    """M, C (C32 with the corrected minus sign) and G in the paper's angles."""
    l1, l2, l3, l5, l6 = p["l1"], p["l2"], p["l3"], p["l5"], p["l6"]
    ma, mc, mbe, mdf = p["ma"], p["mc"], p["mbe"], p["mdf"]
    Iaxx, Iayy, Iazz = p["Ia"]
    Icxx, Icyy, Iczz = p["Ic"]
    Ibexx, Ibeyy, Ibezz = p["Ibe"]
    Idfxx, Idfyy, Idfzz = p["Idf"]
    _, t2, t3 = th
    d1, d2, d3 = thd
    k2 = l1 * (l2 * ma + l3 * mc)
    A = 4 * Ibeyy - 4 * Ibezz + 4 * Icyy - 4 * Iczz + l1**2 * (4 * ma + mc)
    B = -4 * Iayy + 4 * Iazz - 4 * Idfyy + 4 * Idfzz + l2**2 * ma + 4 * l3**2 * mc
    M11 = (
        (
            4 * Iayy
            + 4 * Iazz
            + 8 * p["Ibase"]
            + 4 * Ibeyy
            + 4 * Ibezz
            + 4 * Icyy
            + 4 * Iczz
            + 4 * Idfyy
            + 4 * Idfzz
            + 4 * l1**2 * ma
            + l2**2 * ma
            + l1**2 * mc
            + 4 * l3**2 * mc
        )
        / 8
        + A / 8 * math.cos(2 * t2)
        - B / 8 * math.cos(2 * t3)
        + k2 * math.cos(t2) * math.sin(t3)
    )
    M = np.array(
        [
            [M11, 0.0, 0.0],
            [0.0, Ibexx + Icxx + l1**2 * ma + l1**2 * mc / 4, -k2 / 2 * math.sin(t2 - t3)],
            [0.0, -k2 / 2 * math.sin(t2 - t3), Iaxx + Idfxx + l2**2 * ma / 4 + l3**2 * mc],
        ]
    )
    c11 = (
        -2 * math.sin(t2) * (A * math.cos(t2) + 2 * k2 * math.sin(t3)) * d2
        + 2 * math.cos(t3) * (2 * k2 * math.cos(t2) + B * math.sin(t3)) * d3
    ) / 8
    c12 = -(A * math.sin(2 * t2) + 4 * k2 * math.sin(t2) * math.sin(t3)) * d1 / 8
    c13 = -(-4 * k2 * math.cos(t2) * math.cos(t3) - B * math.sin(2 * t3)) * d1 / 8
    k = k2 / 2
    C = np.array(
        [
            [c11, c12, c13],
            [-c12, 0.0, k * math.cos(t2 - t3) * d3],
            [-c13, -k * math.cos(t2 - t3) * d2, 0.0],
        ]
    )
    G = np.array(
        [
            0.0,
            G0 / 2 * (2 * l1 * ma + 2 * l5 * mbe + l1 * mc) * math.cos(t2),
            G0 / 2 * (l2 * ma + 2 * l3 * mc - 2 * l6 * mdf) * math.sin(t3),
        ]
    )
    return M, C, G


def cavusoglu_in_phi(q, qd):
    """The paper's model at phi (theta3 = phi3 - pi/2; same velocities) plus theory kinematics."""
    th = (q[0], q[1], q[2] - math.pi / 2)
    M, C, G = cavusoglu(th, qd)
    return M, C, G, *kinematics(q, CAV["l1"], CAV["l2"])


CLOSED = {"appendix_b": appendix_b, "cavusoglu": cavusoglu_in_phi}


def random_states(n: int, seed: int):
    rng = np.random.default_rng(seed)
    for _ in range(n):
        yield rng.uniform(-math.pi, math.pi, 3), rng.normal(0.0, 3.0, 3)


@pytest.mark.parametrize("params", ["appendix_b", "cavusoglu"])
def test_pinocchio_agrees_with_the_closed_form_at_random_states(params: str) -> None:
    model = PhantomModel(params)
    worst = dict.fromkeys(("D", "Cqd", "G", "p", "J"), 0.0)
    for q, qd in random_states(200, seed=5):
        D, C, G, pos, J = CLOSED[params](q, qd)
        got = {
            "D": model.mass_matrix(q),
            "Cqd": model.coriolis_vector(q, qd),
            "G": model.gravity(q),
            "p": model.forward_kinematics(q),
            "J": model.jacobian(q),
        }
        want = {"D": D, "Cqd": C @ qd, "G": G, "p": pos, "J": J}
        for key in worst:
            worst[key] = max(worst[key], float(np.max(np.abs(got[key] - want[key]))))
        D2, h = model.mass_and_bias(q, qd)
        np.testing.assert_array_equal(D2, got["D"])
        np.testing.assert_allclose(h, got["Cqd"] + got["G"], rtol=0, atol=1e-15)
    assert max(worst.values()) < 1e-9, worst  # measured: about 1e-16 for every term


@pytest.mark.parametrize("params", ["appendix_b", "cavusoglu"])
def test_closed_form_coriolis_is_the_christoffel_form(params: str) -> None:
    """Sanity of the test's own closed form: D' = C + C^T (so D' - 2C is skew-symmetric)."""
    h = 1e-6
    for q, qd in random_states(20, seed=11):
        D_plus = CLOSED[params](q + h * qd, qd)[0]
        D_minus = CLOSED[params](q - h * qd, qd)[0]
        D_dot = (D_plus - D_minus) / (2 * h)
        C = CLOSED[params](q, qd)[1]
        np.testing.assert_allclose(D_dot, C + C.T, atol=1e-9)


@pytest.mark.parametrize("params", ["appendix_b", "cavusoglu"])
def test_mass_matrix_is_symmetric_positive_definite_everywhere(params: str) -> None:
    """D depends on phi2, phi3 only: a 1-degree grid over the whole torus (beyond the workspace)."""
    model = PhantomModel(params)
    grid = np.radians(np.arange(-180.0, 180.0, 1.0))
    smallest = math.inf
    for a in grid[::3]:
        for b in grid[::3]:
            D = model.mass_matrix([0.7, a, b])
            assert np.max(np.abs(D - D.T)) <= 1e-15 * np.max(np.abs(D))  # symmetric to rounding
            smallest = min(smallest, float(np.linalg.eigvalsh(D)[0]))
    # measured: 2.36e-3 (appendix B), 8.04e-4 (Cavusoglu) kg m^2
    assert smallest > {"appendix_b": 2e-3, "cavusoglu": 7e-4}[params]


@pytest.mark.parametrize("params", ["appendix_b", "cavusoglu"])
def test_torque_free_frictionless_simulation_conserves_energy(params: str) -> None:
    """The arm swings under gravity (after a 50 ms yaw push): energy from the closed form.

    Drift over 2 s at 10 kHz RK4: measured 8.7e-13 J (appendix B, kinetic energy up to 0.65 J)
    and 2.5e-15 J (Cavusoglu, up to 0.15 J); bound 1e-9 J.
    """
    model = PhantomModel(params)
    dev = SimulatedArm(
        model, ArmDeviceParams(encoder_resolution_rad=0.0, initial_position=[0.0, 0.3, 1.0])
    )
    closed = CLOSED[params]

    def energy() -> float:
        D = closed(dev.q, dev.v)[0]
        kinetic = 0.5 * float(dev.v @ D @ dev.v)
        return kinetic + model.potential_energy(dev.q)

    for _ in range(50):
        dev.apply([0.05, 0.0, 0.0])
    e0, drift, kinetic_max = energy(), 0.0, 0.0
    for _ in range(2000):
        dev.apply([0.0, 0.0, 0.0])
        drift = max(drift, abs(energy() - e0))
        kinetic_max = max(kinetic_max, dev.kinetic_energy())
    assert abs(dev.v[0]) > 0.01 and kinetic_max > 0.01  # it did move, yaw included
    assert drift < 1e-9, drift


def test_potential_energy_matches_the_closed_form_and_gravity_is_its_gradient() -> None:
    model = PhantomModel()
    q0 = np.array([0.2, 0.4, 1.1])
    offset = model.potential_energy(q0) - appendix_b_potential(q0)
    for q, _ in random_states(20, seed=3):
        assert model.potential_energy(q) - appendix_b_potential(q) == pytest.approx(
            offset, abs=1e-12
        )


def test_gravity_can_be_left_out_and_viscous_friction_added() -> None:
    q, qd = np.array([0.1, 0.5, 1.2]), np.array([0.3, -0.2, 0.4])
    full, free = PhantomModel(), PhantomModel(gravity=False)
    np.testing.assert_array_equal(free.gravity(q), np.zeros(3))
    np.testing.assert_allclose(
        full.bias_effort(q, qd) - free.bias_effort(q, qd), full.gravity(q), atol=1e-15
    )
    np.testing.assert_allclose(free.mass_matrix(q), full.mass_matrix(q), atol=0)
    damped = PhantomModel(viscous=(0.01, 0.02, 0.03))
    np.testing.assert_allclose(damped.friction(qd), [0.003, -0.004, 0.012])
    np.testing.assert_allclose(
        damped.bias_effort(q, qd) - full.bias_effort(q, qd), [0.003, -0.004, 0.012]
    )
    assert full.dof == 3 and full.joint_names == ("phi1", "phi2", "phi3")
    assert not full.constant_jacobian
    assert "appendix_b" in repr(full)
    np.testing.assert_allclose(full.forward_kinematics(HOME), [0.178, 0.0, -0.221], atol=1e-15)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [({"params": "phantom2"}, "params"), ({"params": 3}, "params"), ({"viscous": -1.0}, "viscous")],
)
def test_phantom_rejects_bad_settings(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        PhantomModel(**kwargs)


def test_phantom_rejects_bad_states() -> None:
    with pytest.raises(ValueError, match=r"^q "):
        PhantomModel().mass_matrix([0.0, 1.0])
    with pytest.raises(ValueError, match=r"^qd "):
        PhantomModel().mass_and_bias([0.0, 1.0, 0.0], [0.0, math.nan, 0.0])


# --- the observer on the Cavusoglu PHANToM -----------------------------------------------------
def forward_euler(model: DeviceModel, c: float, dt: float, samples) -> np.ndarray:
    """The explicit observer the implicit update replaces: z += T c D^-1 (-z + h - tau - c q')."""
    q, qd, tau = samples[0]
    z = -c * np.asarray(qd)
    out = []
    with np.errstate(over="ignore", invalid="ignore"):
        for q, qd, tau in samples:
            D = model.mass_matrix(q)
            w = -z + model.bias_effort(q, qd) - np.asarray(tau) - c * np.asarray(qd)
            z = z + dt * c * np.linalg.solve(D, w)
            out.append(z + c * np.asarray(qd))
    return np.array(out)


def test_implicit_update_is_stable_on_the_cavusoglu_phantom_where_forward_euler_diverges() -> None:
    """c = 2 at 1 kHz: T c / lambda_min(D) is 2.15 to 2.49 over every pose (forward Euler needs
    < 2). The simulated arm carries a 0.37 N tip force and moves under it and gravity; the
    implicit observer (exact model) tracks J^T F, forward Euler on the same samples blows up."""
    model = PhantomModel("cavusoglu")
    force = np.array([0.2, -0.1, 0.3])
    dev = SimulatedArm(
        model,
        ArmDeviceParams(
            encoder_resolution_rad=0.0, external_force_n=tuple(force), velocity="exact"
        ),
    )
    obs = DisturbanceObserver(model, 2.0, dev.dt)
    samples, est, truth = [], [], []
    for _ in range(1500):
        s = dev.sample()
        samples.append((s.q, s.qd, s.effort))
        est.append(obs.update(s.q, s.qd, s.effort))
        truth.append(model.jacobian(s.q).T @ force)
        dev.apply([0.0, 0.0, 0.0])
    est, truth = np.array(est), np.array(truth)
    assert np.all(np.isfinite(est))
    assert np.ptp(np.array([s[0] for s in samples]), axis=0).max() > 0.5  # it moved a lot
    late = slice(500, None)
    rms = np.sqrt(np.mean((est[late] - truth[late]) ** 2, axis=0))
    # the arm whirls (J^T F spans 0.11-0.14 N m per joint): what is left is the observer's lag;
    # measured RMS 0.87 / 1.10 / 0.42 mN m
    assert np.all(rms < 2e-3), rms
    fe = forward_euler(model, 2.0, dev.dt, samples)
    assert not np.all(np.abs(fe[-1]) < 1.0)  # diverged (overflowed to inf or nan)
