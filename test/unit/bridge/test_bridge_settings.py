"""The bridge's settings: profiles fill what a YAML leaves out, and what cannot work is refused."""

from __future__ import annotations

import pytest

from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.settings import SafetySettings, bridge_specs, per_element
from haptic_dob.runtime.params import build

FD = {"state.topic": "/fd/joint_states", "command.topic": "/fd/fd_controller/commands"}


def test_profiles_fill_what_is_left_out() -> None:
    rc = DriverSettings.of({**FD, "profile": "ros2_control_effort"})
    assert (rc.command.type, rc.delay_samples, rc.effort) == ("float64_multi_array", 1, "commanded")
    touch = DriverSettings.of({**FD, "profile": "cartesian_wrench"})
    assert (touch.command.type, touch.delay_samples, touch.cartesian) == ("wrench_stamped", 0, True)
    suite = DriverSettings.of({**FD, "profile": "suite"})
    assert (suite.delay_samples, suite.effort) == (0, "driver")
    given = DriverSettings.of({**FD, "command.delay_samples": 0, "state.effort": "driver"})
    assert (given.delay_samples, given.effort) == (0, "driver")


@pytest.mark.parametrize(
    ("values", "reason"),
    [
        ({"command.topic": "x"}, "state.topic"),
        ({"state.topic": "x"}, "command.topic"),
        ({**FD, "profile": "cartesian_wrench", "command.type": "float64_multi_array"}, "wrench"),
        ({**FD, "command.type": "wrench"}, "cartesian_wrench"),
        ({**FD, "frame.axes": [0, 0, 1]}, "permutation"),
        ({**FD, "state.signs": [0.5]}, r"\+1 or -1"),
        ({**FD, "state.type": "pose", "state.effort": "driver"}, "pose state carries no effort"),
        ({**FD, "profile": "mine"}, "profile must be one of"),
    ],
)
def test_what_cannot_work_is_refused(values: dict[str, object], reason: str) -> None:
    with pytest.raises(ValueError, match=reason):
        DriverSettings.of(values)


def test_a_clamp_is_required_and_a_deadman_needs_its_topic() -> None:
    with pytest.raises(ValueError, match="does not start without one"):
        build(SafetySettings, {}, "safety.").check()
    with pytest.raises(ValueError, match="deadman_topic"):
        build(
            SafetySettings, {"safety.command_limits": [2.0], "safety.deadman": "joy"}, "safety."
        ).check()
    s = build(SafetySettings, {"safety.command_limits": [2.0, 3.0, 4.0]}, "safety.").check()
    assert s.limits_for(3) == (2.0, 3.0, 4.0)
    assert s.rates_for(3) == (2000.0,) * 3
    with pytest.raises(ValueError, match="1 or 2 values"):
        s.limits_for(2)
    with pytest.raises(ValueError, match="must be > 0"):
        per_element("x", [0.0], 3, positive=True)


def test_every_parameter_is_described_and_structural_ones_are_read_only() -> None:
    specs = {s.name: s for s in bridge_specs()}
    assert {
        "profile",
        "state.topic",
        "command.joints",
        "frame.axes",
        "safety.command_limits",
    } <= set(specs)
    assert all(s.description for s in specs.values())
    assert specs["safety.rate_limit"].unit == "N/s" and specs["state.topic"].read_only


def test_the_drivers_topics_must_not_be_the_loops_own() -> None:
    driver = DriverSettings.of({"state.topic": "joint_states", "command.topic": "/fd/cmd"})
    with pytest.raises(ValueError, match="the driver's joint_states is the loop's own topic"):
        driver.check_apart(lambda t: t if t.startswith("/") else f"/{t}")
    DriverSettings.of(FD).check_apart(lambda t: t if t.startswith("/") else f"/haptic/{t}")
    assert DriverSettings.of(FD).describe() == (
        "a ros2_control_effort driver: state /fd/joint_states (joint_states, reliable), "
        "command /fd/fd_controller/commands (float64_multi_array, reliable)"
    )
