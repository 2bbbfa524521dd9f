"""Excitation trajectories for an arm's identification (``haptic-excite``): a finite Fourier
series from rest to rest, designed within the arm's limits, written and read as a file."""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.identification import arm_parameters as ap
from haptic_dob.identification.arm_excitation import ExcitationLimits, FourierExcitation
from haptic_dob.identification.arm_excitation_design import design_excitation
from support.paths import tool

ROOT = Path(__file__).resolve().parents[3]
ARM3 = ROOT / "config" / "urdf" / "arm3.urdf"
ARM7 = ROOT / "config" / "urdf" / "arm7.urdf"
SLAVE = ROOT / "config" / "excitation" / "arm7_slave.yaml"


def within(model: UrdfModel, exc: FourierExcitation, limits: ExcitationLimits) -> dict:
    """The trajectory's extremes over a period at 1 kHz, each as a share of its limit (<= 1
    holds), the tip's box and the effort the model needs."""
    t = np.arange(0.0, exc.period_s, 1e-3)
    q, v, a = exc.motion(t)
    rng = np.array(model.position_limits)
    margin = limits.margin_rad
    tau = np.array(
        [model.inverse_dynamics(*s) for s in zip(q[::10], v[::10], a[::10], strict=True)]
    )
    tips = np.array([model.forward_kinematics(qk) for qk in q[::10]])
    return {
        "position": bool(np.all(q >= rng[:, 0] + margin) and np.all(q <= rng[:, 1] - margin)),
        "speed": float(
            np.max(
                np.abs(v)
                / np.minimum(
                    np.array(model.velocity_limits) * limits.speed_share, limits.max_speed_rad_s
                )
            )
        ),
        "accel": float(np.max(np.abs(a)) / limits.max_accel_rad_s2),
        "effort": float(
            np.max(np.abs(tau) / (np.array(model.effort_limits) * limits.effort_share))
        ),
        "box": bool(
            limits.box_lo is None
            or (np.all(tips >= limits.box_lo) and np.all(tips <= limits.box_hi))
        ),
    }


def test_the_series_starts_and_ends_each_period_at_rest_where_it_was_told(tmp_path) -> None:
    exc = FourierExcitation(
        ("a", "b"),
        4.0,
        (0.3, -0.2),
        ((0.2, -0.5, 0.3), (0.1, 0.1, -0.2)),
        ((0.4, 0.1, -0.2), (0.2, -0.4, 0.2)),
    )
    q, v, acc = exc.motion(np.array([0.0, 4.0, 8.0]))
    np.testing.assert_allclose(q, [[0.3, -0.2]] * 3, atol=1e-12)
    np.testing.assert_allclose(v, 0.0, atol=1e-12)
    np.testing.assert_allclose(acc, 0.0, atol=1e-12)
    t = np.linspace(0.1, 3.9, 50)  # the derivatives are the series'
    q, v, acc = exc.motion(t)
    q2, v2, _ = exc.motion(t + 1e-6)
    np.testing.assert_allclose((q2 - q) / 1e-6, v, atol=1e-5)
    np.testing.assert_allclose((v2 - v) / 1e-6, acc, atol=1e-4)
    path = tmp_path / "traj.yaml"
    exc.save(path, "a note\non two lines")
    assert FourierExcitation.load(path) == exc
    assert path.read_text().splitlines()[2] == "# on two lines"
    path.write_text("joints: [a]\nperiod_s: 1\nstart: [0, 1]\nsine: [[0]]\ncosine: [[0]]\n")
    with pytest.raises(ValueError, match="coefficients do not match its joints"):
        FourierExcitation.load(path)


def test_the_design_keeps_every_limit_and_conditions_the_regressor() -> None:
    """arm3 from a start posture, a box for the tip above z = 0.05 m: every limit holds on a
    1 kHz grid (the design's own points are 60 a period), and the condition number is below
    the best random start's and far below a random series' within the limits."""
    model = UrdfModel(ARM3, "tool")
    limits = ExcitationLimits(
        max_speed_rad_s=1.0, box_lo=(-1.0, -1.0, 0.05), box_hi=(1.0, 1.0, 1.0)
    )
    d = design_excitation(
        model, [0.3, 0.5, -0.8], period_s=6.0, harmonics=4, limits=limits, iterations=15
    )
    found = within(model, d.excitation, limits)
    assert found["position"] and found["box"], found
    assert max(found["speed"], found["accel"], found["effort"]) <= 1.0 + 1e-9, found
    assert d.condition_number <= d.start_condition_number
    t = np.arange(0.0, 6.0, 0.1)
    W = ap.regressor(model, *d.excitation.motion(t), np.sign(d.excitation.motion(t)[1]))
    base = ap.base_set(ap.regressor(model, *ap.reference_states(model, 300))).base
    assert ap.condition_number(W[:, base]) < 3.0 * d.condition_number  # the 60 points' figure
    with pytest.raises(ValueError, match="the start breaks a limit"):
        design_excitation(
            model, [0.3, 0.5, -0.8], limits=ExcitationLimits(box_lo=(0, 0, 0.5), box_hi=(1, 1, 1))
        )


def test_the_slaves_excitation_file_keeps_the_arms_limits() -> None:
    """``config/excitation/arm7_slave.yaml`` (``haptic-excite``, its command in the file):
    within arm7's limits (less 0.1 rad), half its speed limit (at most 1.5 rad/s), 6 rad/s^2,
    80 % of its efforts and the box it names, from the slave's start posture."""
    exc = FourierExcitation.load(SLAVE)
    assert exc.start == (0.0, 0.5, 0.0, -1.5, 0.0, 1.0, 0.0)
    assert "haptic-excite --urdf config/urdf/arm7.urdf" in SLAVE.read_text()
    limits = ExcitationLimits(box_lo=(-0.6, -0.8, 0.25), box_hi=(0.8, 0.8, 1.2))
    found = within(UrdfModel(ARM7, "tool"), exc, limits)
    assert found["position"] and found["box"], found
    assert max(found["speed"], found["accel"], found["effort"]) <= 1.0, found


def test_the_command_writes_the_file_and_refuses_bad_input_in_one_line(tmp_path) -> None:
    out = tmp_path / "traj.yaml"
    args = [
        tool("haptic-excite"),
        "--urdf",
        str(ARM3),
        "--tip-frame",
        "tool",
        "--start",
        "0.3,0.5,-0.8",
    ]
    done = subprocess.run(
        [
            *args,
            "--out",
            str(out),
            "--period",
            "5",
            "--harmonics",
            "3",
            "--iterations",
            "5",
            "--json",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 0, done.stderr
    figures = json.loads(done.stdout)
    assert figures["joints"] == ["joint1", "joint2", "joint3"] and figures["condition_number"] > 1
    assert FourierExcitation.load(out).period_s == 5.0
    for extra, message in (
        (["--start", "1,2"], "--start needs 3 numbers"),
        (["--box", "0,0,0.5,1,1,1"], "the start breaks a limit"),
        (["--tip-frame", "nope"], "tip_frame 'nope' is not a frame"),
        (["--period", "-1"], "--period must be > 0"),
    ):
        bad = subprocess.run(
            [*args, "--out", str(out), *extra], capture_output=True, text=True, timeout=300
        )
        assert bad.returncode == 2, (extra, bad.stderr)
        assert message in bad.stderr and "Traceback" not in bad.stderr
        assert bad.stderr.strip().splitlines()[-1].startswith("ERROR:")
