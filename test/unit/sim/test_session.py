"""The batch runner: determinism, the cycle contract, configuration and OL transparency."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.analysis import mass_damper_band_edge_hz
from haptic_dob.core.environment import VirtualWall
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for


def short(**groups) -> SessionConfig:
    return SessionConfig().replace(loop__duration_s=3.0, **groups)


def test_same_seed_same_session_to_the_bit() -> None:
    a, b = run_session(short()), run_session(short())
    for name in ("x_true", "q", "qd", "command", "force_measured", "force_estimated"):
        assert np.array_equal(getattr(a, name), getattr(b, name)), name
    c = run_session(short(loop__seed=1))
    assert not np.array_equal(a.q, c.q)


def test_command_k_is_held_over_the_next_period() -> None:
    """Cycle contract: the effort sample k+1 reports is command k, after saturation."""
    r = run_session(short(law=law_for("CL", 25.0)))
    assert np.array_equal(r.effort[1:], np.clip(r.command[:-1], -4.0, 4.0))
    assert r.effort[0] == 0.0
    assert np.any(np.abs(r.command) > 4.0) or np.any(np.abs(r.effort) == 4.0)


def test_command_k_uses_sample_k() -> None:
    """OL: command k is the wall force of the encoder position of sample k, no extra delay."""
    r = run_session(short())
    expected = -800.0 * np.maximum(r.q, 0.0)
    np.testing.assert_allclose(r.command, np.clip(expected, -4.0, 4.0), atol=1e-12)


def test_yaml_config_is_the_default_session_with_an_identified_model_and_its_gain(root) -> None:
    """The config is the code's default session, except what the observer and the controller
    assume (the model identified from the plant, test_identified_model) and the observer gain."""
    cfg = SessionConfig.from_yaml(root / "config" / "slide_sim.yaml")
    default = SessionConfig()
    assert cfg.replace(model=default.model, observer=default.observer) == default
    assert cfg.model != default.model and cfg.device == default.device  # the plant: the default
    assert cfg.observer.gain == 7.0 and cfg.observer.output_limit == default.observer.output_limit


def test_node_params_take_the_plant_from_the_device_and_the_model_from_the_observer() -> None:
    cfg = SessionConfig.from_node_params(
        {
            "/**": {"slide.mass_kg": 0.45, "rate_hz": 500.0},
            "device_node": {"plant.mass_kg": 0.5, "plant.amplifier_lag_s": 0.0},
            "observer_node": {"gain": 20.0},
            "controller_node": {"mode": "DOB", "kf": 1},
            "environment_node": {"stiffness_n_per_m": 1600},
        }
    )
    assert cfg.device.mass_kg == 0.5 and cfg.device.amplifier_lag_s == 0.0
    assert cfg.model.mass_kg == 0.45
    assert cfg.loop.rate_hz == 500.0 and cfg.observer.gain == 20.0
    assert cfg.law.mode.value == "DOB" and cfg.law.kf == 1.0
    assert cfg.wall.stiffness_n_per_m == 1600.0


def test_observer_and_controller_must_assume_one_model() -> None:
    with pytest.raises(ValueError, match="assume different slide models"):
        SessionConfig.from_node_params(
            {"observer_node": {"slide.mass_kg": 0.45}, "controller_node": {"slide.mass_kg": 0.5}}
        )
    with pytest.raises(ValueError, match=r"the device's slide\.axis differs"):
        SessionConfig.from_node_params({"device_node": {"slide.axis": [0.0, 1.0, 0.0]}})


@pytest.mark.parametrize(
    ("params", "match"),
    [
        ({"controller_node": {"kf": -1.0}}, "kf must be >= 0"),
        ({"controller_node": {"mode": "PID"}}, "mode must be one of"),
        ({"environment_node": {"normal": [0.0, 1.0]}}, "normal must have 3"),
        ({"device_node": {"hand.behaviour": "dance"}}, "hand.behaviour must be one of"),
        ({"/**": {"rate_hz": "fast"}}, "rate_hz must be a number"),
    ],
)
def test_node_params_are_checked_with_a_reason(params: dict, match: str) -> None:
    with pytest.raises(ValueError, match=match):
        SessionConfig.from_node_params(params)


@pytest.mark.slow
@pytest.mark.parametrize("K", [800.0, 1600.0])
def test_open_loop_transparency_matches_the_mass_damper(K: float) -> None:
    """OL on the mass-damper's band edge: 3.78 Hz at 800 N/m and 5.34 Hz at 1600 N/m (+-10 %),
    the hand pushing to its depth."""
    cfg = SessionConfig().replace(wall=VirtualWall(K))
    summary = run_session(cfg).summary()
    assert summary.in_contact_pct > 99.0
    assert summary.bandwidth_hz == pytest.approx(mass_damper_band_edge_hz(K, 0.416), rel=0.10)
