"""An arm's whole model from its joint states (``haptic-identify --inertial``).

The teleoperation slave (``config/teleop_sim.yaml``) is a simulated 7-DOF arm whose truth
(``config/urdf/arm7_truth.urdf``: link masses 10-20 % off, centres of mass 1-2 cm away, joint
friction and armature) its URDF (``arm7.urdf``) does not state; its controller plays the
excitation file on the CAD model. The identification knows only the URDF and the joint
positions and efforts (a driver's bag without velocities). These tests use a 15 s record; the
60 s case is ``test/unit/teleop/test_slave_model.py``.
"""

from __future__ import annotations

import dataclasses
import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.identification.arm_excitation import FourierExcitation
from haptic_dob.identification.arm_model import Record, identify_arm_model
from haptic_dob.identification.filters import IdentificationError
from haptic_sim.arm.model_bench import free_motion, held_force
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.slave_model import (
    cad_urdf,
    control_model,
    identify_slave,
    play_excitation,
    slave_bench,
)
from support.joint_bags import write_arm_bag
from support.paths import tool

ROOT = Path(__file__).resolve().parents[3]
CONFIG = ROOT / "config" / "teleop_sim.yaml"
ARM7 = ROOT / "config" / "urdf" / "arm7.urdf"
EXCITATION = ROOT / "config" / "excitation" / "arm7_slave.yaml"


@pytest.fixture(scope="module")
def config() -> TeleopConfig:
    return TeleopConfig.from_yaml(CONFIG)


@pytest.fixture(scope="module")
def record(config) -> Record:
    return play_excitation(config, FourierExcitation.load(EXCITATION), 15.0)


def scaled(exc: FourierExcitation, k: float) -> FourierExcitation:
    """The excitation with every coefficient times ``k`` (its motion k times as large)."""
    sine = tuple(tuple(k * v for v in row) for row in exc.sine)
    cosine = tuple(tuple(k * v for v in row) for row in exc.cosine)
    return dataclasses.replace(exc, sine=sine, cosine=cosine)


def test_a_short_bag_gives_a_consistent_model_whose_observer_reads_free_motion_right(
    config, record
) -> None:
    """15 s (1.5 periods): the held-out residual falls from CAD's 85 % of the worst joint's
    torque span to 0.99 % (measured); each joint's friction within 0.05 % of the truth's, its
    armature within 3 % (measured); every link consistent; an observer on the model reads free
    motion under 0.2 N (measured 0.046 N; CAD 6 N) and a held 5 N within 3 % (0.005 %)."""
    fit = identify_slave(config, record)
    assert fit.residual_pct < 3.0 < 10.0 < fit.residual_cad_pct, fit.residual_pct
    truth = slave_bench(config).truth
    for j, b, fc, arm in zip(fit.joints, truth.viscous, truth.coulomb, truth.armature, strict=True):
        assert j.viscous == pytest.approx(b, rel=0.05), j
        assert j.coulomb == pytest.approx(fc, rel=0.05), j
        if j.joint not in ("joint1", "joint2"):  # theirs is carried by the links' inertia
            assert j.armature == pytest.approx(arm, rel=0.1), j
    for lf in fit.links:
        assert lf.mass > 0.0 and lf.pseudo_inertia_min > 0.0, lf
        assert all(lo <= c <= hi for lo, c, hi in zip(lf.box_lo, lf.com, lf.box_hi, strict=True))
    observer = UrdfModel(fit.urdf(cad_urdf(config), "test"), "tool")
    bench, control = slave_bench(config), control_model(config)
    assert np.max(free_motion(bench, control, observer)) < 0.2
    held = held_force(bench, control, observer)
    assert np.linalg.norm(held - [0.0, 0.0, -5.0]) < 0.03 * 5.0, held


def test_the_command_reads_a_drivers_bag_and_writes_the_urdf_the_observer_loads(
    tmp_path, config, record
) -> None:
    bag = write_arm_bag(tmp_path / "bag", record)
    out = tmp_path / "identified.urdf"
    args = ["--urdf", str(ARM7), "--tip-frame", "tool", "--inertial", "--turn-cutoff-hz", "50"]
    done = subprocess.run(
        [tool("haptic-identify"), str(bag), *args, "--json", "--write-urdf", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert done.returncode == 0, done.stderr
    (line,) = done.stdout.splitlines()
    figures = json.loads(line)
    assert figures["residual_pct"] < 3.0 and figures["joints"][0]["joint"] == "joint1"
    loaded = UrdfModel(out, "tool")
    np.testing.assert_allclose(loaded.armature, [j["armature"] for j in figures["joints"]])
    np.testing.assert_allclose(
        loaded.coulomb_speed, [j["coulomb_speed"] for j in figures["joints"]]
    )
    fit = identify_slave(config, record)  # the command's figures are the library's
    assert figures["residual_pct"] == pytest.approx(fit.residual_pct, rel=1e-6)


def test_too_little_excitation_is_refused_naming_what_it_does_not_see(config) -> None:
    """The excitation at a twentieth of its size: the record cannot tell the links' inertias
    apart (its accelerations are a twentieth, their regressor columns in the noise), so the
    identification refuses, naming them, instead of fitting them to noise."""
    exc = scaled(FourierExcitation.load(EXCITATION), 0.05)
    small = play_excitation(config, exc, 8.0)
    with pytest.raises(
        IdentificationError, match=r"too little excitation: the record does not see link"
    ):
        identify_arm_model(cad_urdf(config), "tool", small)


@pytest.mark.parametrize(
    ("kind", "message"),
    [
        ("no effort", "carries no effort for joint 'joint1'"),
        ("other joints", "has no joint 'joint1'"),
        ("still", "too little motion: 0 samples to fit, 0 held out, once the filters"),
    ],
)
def test_a_bag_it_cannot_use_gets_one_line_and_exit_2(tmp_path, config, kind, message) -> None:
    n = 3000
    still = Record(
        np.arange(n, dtype=np.int64) * 1_000_000,
        np.tile([0.0, 0.5, 0.0, -1.5, 0.0, 1.0, 0.0], (n, 1)),
        np.zeros((n, 7)),
        tuple(f"joint{i}" for i in range(1, 8)),
    )
    names = [f"arm_joint{i}" for i in range(1, 8)] if kind == "other joints" else None
    bag = write_arm_bag(tmp_path / "bag", still, effort=kind != "no effort", names=names)
    done = subprocess.run(
        [
            tool("haptic-identify"),
            str(bag),
            "--urdf",
            str(ARM7),
            "--tip-frame",
            "tool",
            "--inertial",
        ],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert done.returncode == 2, done.stderr
    (line,) = done.stderr.strip().splitlines()
    assert line.startswith("ERROR:") and message in line, line


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--inertial"], "--inertial and --write-urdf need --urdf"),
        (
            ["--urdf", "x.urdf", "--tip-frame", "t", "--write-urdf", "o.urdf"],
            "--write-urdf needs --inertial",
        ),
        (
            ["--urdf", "x.urdf", "--tip-frame", "t", "--inertial", "--write-yaml", "o.yaml"],
            "--write-urdf",
        ),
    ],
)
def test_option_mistakes_are_named(tmp_path, args, message) -> None:
    done = subprocess.run(
        [tool("haptic-identify"), str(tmp_path / "bag"), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert done.returncode == 2 and message in done.stderr and "Traceback" not in done.stderr


def test_a_held_start_and_lost_states_are_left_out(config, record) -> None:
    """The record as a lab's bag has it: 2 s at the start with the arm held still by something
    the model lacks (an inkwell, a hand; zero effort) and 20 runs of 2-8 states lost on the
    way. The fit leaves out the samples whose filters reach the held stretch or a gap: each
    joint's friction within 5 % of the truth's, as on the whole record."""
    period = int(np.median(np.diff(record.stamps_ns)))
    n0 = round(2.0e9 / period)
    stamps = np.concatenate([record.stamps_ns[0] - period * np.arange(n0, 0, -1), record.stamps_ns])
    position = np.vstack([np.repeat(record.position[:1], n0, axis=0), record.position])
    effort = np.vstack([np.zeros((n0, record.effort.shape[1])), record.effort])
    rng = np.random.default_rng(0)
    lost = np.zeros(len(stamps), dtype=bool)
    for start in rng.choice(np.arange(n0, len(stamps) - 10), 20, replace=False):
        lost[start : start + rng.integers(2, 9)] = True
    held = Record(stamps[~lost], position[~lost], effort[~lost], record.names)
    fit = identify_slave(config, held)
    truth = slave_bench(config).truth
    for j, b, fc in zip(fit.joints, truth.viscous, truth.coulomb, strict=True):
        assert j.viscous == pytest.approx(b, rel=0.05), j
        assert j.coulomb == pytest.approx(fc, rel=0.05), j
