"""The simulated Cartesian device: three slides' physics, one hand in 3-D, the driver's sample."""

from __future__ import annotations

import math

import numpy as np
import pytest

from haptic_dob.core.models.point_mass import PointMassModel
from haptic_sim.device.factory import build_device, simulation_specs
from haptic_sim.device.settings import device_node_specs
from haptic_sim.hand import HandParams
from haptic_sim.point_mass.device import PointMassDeviceParams, SimulatedPointMass
from haptic_sim.slide.device import SimulatedSlide

MASS, VISCOUS = (0.25, 0.22, 0.28), (1.0, 0.8, 1.2)
IDEAL = {
    "coulomb_n": (0.0, 0.0, 0.0),
    "stiction_ratio": 1.0,
    "stribeck_velocity_m_per_s": 0.0,
    "amplifier_lag_s": 0.0,
    "encoder_resolution_m": 1e-12,
    "encoder_noise_m": 0.0,
}


def test_each_axis_follows_its_own_closed_form() -> None:
    """Viscous axes under held forces from rest: ``x(t) = (F / b) (t - tau (1 - e^(-t / tau)))``,
    ``tau = m / b``, each axis with its own m and b; the sample is the driver's."""
    device = SimulatedPointMass(PointMassDeviceParams(MASS, VISCOUS, **IDEAL))
    force = (0.8, -1.5, 2.0)
    for _ in range(300):
        device.apply(force)
    t = 300 * device.dt
    for i in range(3):
        tau = MASS[i] / VISCOUS[i]
        x = force[i] / VISCOUS[i] * (t - tau * (1.0 - math.exp(-t / tau)))
        assert device.position[i] == pytest.approx(x, rel=1e-9)
    s = device.sample()
    assert s.k == 300 and s.stamp_ns == 300_000_000 and s.effort == force
    assert s.ee_position == s.q == pytest.approx(device.position, abs=1e-12)
    assert s.ee_velocity == s.qd
    assert device.model.joint_names == ("fd_x", "fd_y", "fd_z")


def test_its_truth_is_three_slides_with_the_model_missing_stiction_and_lag() -> None:
    """Axis i is the simulated slide with axis i's truth, sample for sample; the rigid part is
    the point-mass model of its masses and friction."""
    d = PointMassDeviceParams(encoder_noise_m=0.0)  # the noise's draws: the next test
    device = SimulatedPointMass(d, seed=3)
    assert isinstance(device.model, PointMassModel)
    np.testing.assert_array_equal(device.model.mass_kg, d.mass_kg)
    np.testing.assert_array_equal(device.model.coulomb_n, d.coulomb_n)
    slides = [
        SimulatedSlide(d.axis(i), hand=HandParams(behaviour="none"), axis=e)
        for i, e in enumerate(np.eye(3))
    ]
    rng = np.random.default_rng(1)
    for _ in range(500):
        u = rng.uniform(-0.3, 0.3, 3).tolist()
        device.apply(u)
        for i, s in enumerate(slides):
            s.apply([u[i]])
            assert device.sample().q[i] == s.sample().q[0]
    assert d.axis(2).stiction_ratio == 1.5 and d.axis(2).amplifier_lag_s == 1e-4


def test_stiction_holds_an_axis_that_the_others_leave() -> None:
    """1.2 Fc on every axis: above the model's Coulomb level, below the breakaway (1.5 Fc)."""
    d = PointMassDeviceParams(coulomb_n=(0.1, 0.1, 0.1), encoder_noise_m=0.0)
    device = SimulatedPointMass(d)
    for _ in range(200):
        device.apply((0.12, 0.16, -0.12))
    x, y, z = device.position
    assert x == 0.0 and z == 0.0 and y > 1e-4


def test_the_encoder_counts_after_its_noise() -> None:
    """Readings are whole counts; the noise moves some by a count from the noise-free ones."""

    def readings(noise_m: float) -> np.ndarray:
        d = PointMassDeviceParams(encoder_resolution_m=1e-5, encoder_noise_m=noise_m)
        device = SimulatedPointMass(d, seed=0)
        out = []
        for _ in range(400):
            device.apply((0.5, 0.0, 0.0))
            out.append(device.sample().q[0])
        return np.asarray(out)

    noisy, exact = readings(3e-6), readings(0.0)
    counts = noisy / 1e-5
    np.testing.assert_allclose(counts, np.round(counts), atol=1e-6)
    off = np.round(np.abs(noisy - exact) / 1e-5)
    assert off.max() == 1 and 0.1 < np.mean(off) < 0.6


def test_the_hand_pulls_along_its_direction_and_holds_the_rest() -> None:
    """A push-and-hold hand along (1, 1, 0)/sqrt(2), no actuator effort: the handle settles
    where the grip's spring balances friction, on the push's line; the force is along it."""
    d = PointMassDeviceParams(
        coulomb_n=(0.0, 0.0, 0.0), hand_direction=(1.0, 1.0, 0.0), initial_position=(0, 0, 0.02)
    )
    hand = HandParams(behaviour="push_hold", offset_m=0.01, ramp_s=0.2)
    device = SimulatedPointMass(d, hand=hand, seed=2)
    for _ in range(3000):
        device.prepare()
        device.apply((0.0, 0.0, 0.0))
    x, y, z = device.position
    assert x == pytest.approx(0.01 / math.sqrt(2.0), rel=1e-3)
    assert y == pytest.approx(x, rel=1e-6) and z == pytest.approx(0.02, abs=1e-9)
    device.apply((-1.0, -1.0, 0.0))  # the actuators push back: the hand holds against them
    for _ in range(2000):
        device.apply((-1.0, -1.0, 0.0))
    fx, fy, fz = device.sample().hand_force
    assert fx == pytest.approx(1.0, rel=1e-3) and fy == pytest.approx(1.0, rel=1e-3)
    assert fz == pytest.approx(0.0, abs=1e-9)


def test_apply_refuses_a_bad_effort_and_changes_nothing() -> None:
    device = SimulatedPointMass()
    before = device.sample()
    for bad in ((1.0, 2.0), (0.0, float("nan"), 0.0)):
        with pytest.raises(ValueError, match="effort must"):
            device.apply(bad)
    assert device.sample() == before and device.k == 0


def test_the_device_node_builds_it_from_its_parameters() -> None:
    names = {s.name for s in device_node_specs()}
    assert {"cartesian.mass_kg", "cartesian.encoder_noise_m", "point_mass.joint_names"} <= names
    assert "point_mass.mass_kg" not in names  # the model the others assume, not the plant
    specs = {s.name: s for s in simulation_specs()}
    assert specs["cartesian.mass_kg"].read_only and specs["cartesian.mass_kg"].length == 3
    device = build_device(
        {
            "model": "point_mass",
            "point_mass.joint_names": ["x", "y", "z"],
            "cartesian.mass_kg": [0.3, 0.3, 0.3],
            "cartesian.max_force_n": 9.0,
            "rate_hz": 500.0,
            "hand.behaviour": "none",
        }
    )
    assert isinstance(device, SimulatedPointMass)
    assert device.model.joint_names == ("x", "y", "z") and device.max_effort == (9.0,) * 3
    assert device.period_ns == 2_000_000 and device.model.mass_kg.tolist() == [0.3] * 3
    with pytest.raises(ValueError, match=r"cartesian\.mass_kg must have 3 elements"):
        build_device({"model": "point_mass", "cartesian.mass_kg": [0.3]})


def test_a_seed_gives_the_same_run() -> None:
    hand = HandParams(behaviour="semi_random", offset_m=0.005, amplitude_m=0.002)
    runs = []
    for _ in range(2):
        device = SimulatedPointMass(hand=hand, seed=11)
        for _ in range(300):
            device.apply((0.1, -0.1, 0.2))
        runs.append(device.sample())
    assert runs[0] == runs[1]
