"""An arm's joint friction from a bag of its joint states (``haptic-identify --urdf``).

The simulated arm (``SimulatedArm``: RK4 on the truth model, 1e-5 rad encoders) has viscous and
Coulomb joint friction the URDF does not state; a PD controller swings it through a sum of sines
per joint. The identification knows only the URDF's rigid body and the recorded joint states.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.bag.joints import JointStates, read_joints
from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models.factory import build_model
from haptic_dob.identification.arm_friction import identify_arm_friction
from haptic_dob.identification.filters import IdentificationError
from haptic_dob.runtime.params import load_node_params
from haptic_msgs_py import wire
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm
from support.paths import tool

ROOT = Path(__file__).resolve().parents[3]
ARM3 = ROOT / "config" / "urdf" / "arm3.urdf"
VISCOUS = [0.05, 0.08, 0.03]  # N m s/rad
COULOMB = [0.10, 0.15, 0.05]  # N m
START = np.array([0.3, 0.5, -0.8])


def swing(seconds: float) -> JointStates:
    """The arm with friction, PD (+ the rigid model's gravity) on a sum of sines per joint."""
    truth = UrdfModel(ARM3, "tool", viscous=VISCOUS, coulomb=COULOMB)
    rigid = UrdfModel(ARM3, "tool")  # arm3.urdf states no friction
    dev = SimulatedArm(
        truth, ArmDeviceParams(encoder_resolution_rad=1e-5, initial_position=START.tolist())
    )
    freqs = np.array([[0.13, 0.41, 0.77], [0.19, 0.53, 0.91], [0.23, 0.61, 1.07]])
    amp = np.array([0.5, 0.4, 0.6]) / 3.0
    stamps, q_, u_ = [], [], []
    for k in range(round(seconds * 1000)):
        s = dev.sample()
        q, qd = np.array(s.q), np.array(s.qd)
        stamps.append(s.stamp_ns)
        q_.append(q)
        u_.append(s.effort)
        ref = START + amp * np.sin(2 * np.pi * freqs * k * 1e-3).sum(axis=1)
        dev.apply((rigid.gravity(q) + 30.0 * (ref - q) - 3.0 * qd).tolist())
    return JointStates(np.array(stamps), truth.joint_names, np.array(q_), np.array(u_))


@pytest.fixture(scope="module")
def record() -> JointStates:
    return swing(15.0)


def write_bag(path: Path, js: JointStates) -> Path:
    """The record as a driver's ``/joint_states`` bag (every joint in one message)."""
    from rosbags.rosbag2 import StoragePlugin, Writer

    writer = Writer(path, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.open()
    try:
        conn = writer.add_connection(
            "/joint_states", "sensor_msgs/msg/JointState", typestore=wire.TYPESTORE
        )
        msg = wire.joint_state(list(js.names), "base_link")
        for st, q, u in zip(js.stamps_ns.tolist(), js.position, js.effort, strict=True):
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(int(st), 10**9)
            msg.position, msg.velocity, msg.effort = q, np.zeros(len(q)), np.asarray(u)
            writer.write(conn, int(st) + 1, wire.encode(msg))
    finally:
        writer.close()
    return path


@pytest.mark.slow
def test_the_friction_beyond_the_urdf_is_found_and_explains_held_out_data(record) -> None:
    rigid = UrdfModel(ARM3, "tool")
    fit = identify_arm_friction(
        rigid, record.stamps_ns, record.position, record.effort, record.names
    )
    for j, b, fc in zip(fit.joints, VISCOUS, COULOMB, strict=True):
        assert j.viscous == pytest.approx(b, rel=0.05), j  # measured within 1 %
        assert j.coulomb == pytest.approx(fc, rel=0.10), j  # measured within 0.5 %
        assert j.heldout_rms < 0.1 * j.heldout_rms_rigid, j  # measured 1.3-2 %


@pytest.mark.slow
def test_the_turn_searched_through_the_fits_own_low_pass_is_the_default(record) -> None:
    """``turn_cutoff_hz`` equal to ``cutoff_hz`` takes the search's second set of filters (built
    and applied apart) and must give the default fit exactly; a wider one changes the turn."""
    rigid = UrdfModel(ARM3, "tool")
    args = (rigid, record.stamps_ns, record.position, record.effort, record.names)
    plain = identify_arm_friction(*args)
    same = identify_arm_friction(*args, turn_cutoff_hz=20.0)
    assert same == plain
    wide = identify_arm_friction(*args, turn_cutoff_hz=50.0)
    assert [j.coulomb_speed for j in wide.joints] != [j.coulomb_speed for j in plain.joints]
    with pytest.raises(IdentificationError, match=r"turn_cutoff_hz must be at least .*20 Hz"):
        identify_arm_friction(*args, turn_cutoff_hz=5.0)  # narrower than the fit's
    with pytest.raises(IdentificationError, match=r"turn_cutoff_hz: cutoff must be in \(0, 250\)"):
        identify_arm_friction(*args, turn_cutoff_hz=300.0)


@pytest.mark.slow
def test_a_continuous_joint_wrapped_by_its_driver_gives_the_same_friction(record) -> None:
    """arm3's base yaw (joint1) turned by 2.8 rad and wrapped to (-pi, pi], as a driver reports
    a continuous joint: the yaw does not enter the dynamics, so the fit must not change beyond
    rounding (the sign of a velocity that the encoder makes exactly 0 at rest flips with it:
    measured 0.1 %). Without unwrapping, each wrap is a 2 pi / T velocity spike."""
    wrapped = record.position.copy()
    wrapped[:, 0] = np.angle(np.exp(1j * (wrapped[:, 0] + 2.8)))
    assert np.max(np.abs(np.diff(wrapped[:, 0]))) > 6.0  # it does wrap
    rigid = UrdfModel(ARM3, "tool")
    plain = identify_arm_friction(
        rigid, record.stamps_ns, record.position, record.effort, record.names
    )
    turned = identify_arm_friction(rigid, record.stamps_ns, wrapped, record.effort, record.names)
    for a, b in zip(plain.joints, turned.joints, strict=True):
        assert b.viscous == pytest.approx(a.viscous, rel=0.01)
        assert b.coulomb == pytest.approx(a.coulomb, rel=0.01)


@pytest.mark.slow
def test_cli_reads_the_arms_bag_and_writes_the_friction_the_observer_loads(
    tmp_path, record
) -> None:
    bag = write_bag(tmp_path / "bag", record)
    assert read_joints(bag).names == record.names
    model = tmp_path / "friction.yaml"
    out = subprocess.run(
        [tool("haptic-identify"), str(bag), "--urdf", str(ARM3), "--tip-frame", "tool",
         "--json", "--write-yaml", str(model)],
        capture_output=True,
        text=True,
        timeout=120,
    )  # fmt: skip
    assert out.returncode == 0, out.stderr
    joints = json.loads(out.stdout)["joints"]
    assert [j["joint"] for j in joints] == list(record.names)
    params = load_node_params(model)["observer_node"]
    loaded = build_model({"model": "urdf", "urdf_path": str(ARM3), "tip_frame": "tool", **params})
    np.testing.assert_allclose(loaded.viscous, [j["viscous"] for j in joints])
    np.testing.assert_allclose(loaded.coulomb, [j["coulomb"] for j in joints])
    table = subprocess.run(
        [tool("haptic-identify"), str(bag), "--urdf", str(ARM3), "--tip-frame", "tool"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert table.returncode == 0 and "held-out RMS" in table.stdout


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["--urdf", str(ARM3)], "--urdf needs --tip-frame"),
        (["--urdf", str(ARM3), "--tip-frame", "nope"], "tip_frame 'nope' is not a frame"),
        (["--urdf", str(ARM3), "--tip-frame", "tool", "--joints", "joint1,elbow"], "elbow"),
        (["--urdf", str(ARM3), "--tip-frame", "tool"], "too short: 50 samples"),
        (["--turn-cutoff-hz", "50"], "--turn-cutoff-hz needs --urdf"),
        (["--urdf", str(ARM3), "--tip-frame", "tool", "--turn-cutoff-hz", "0"], "positive"),
        (["--urdf", str(ARM3), "--tip-frame", "tool", "--turn-cutoff-hz", "nan"], "positive"),
    ],
)
def test_bad_arm_arguments_and_records_get_one_line_and_exit_2(tmp_path, args, message) -> None:
    still = np.zeros((50, 3))
    short = JointStates(np.arange(50) * 1_000_000, ("joint1", "joint2", "joint3"), still, still)
    out = subprocess.run(
        [tool("haptic-identify"), str(write_bag(tmp_path / "bag", short)), *args],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 2, out.stderr
    assert message in out.stderr and "Traceback" not in out.stderr
    assert out.stderr.strip().splitlines()[-1].startswith("ERROR:")  # after a usage, if any


def test_a_topic_that_interleaves_an_arms_and_a_grippers_states_gives_the_arms(tmp_path) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer

    from haptic_dob.bag.errors import BagError

    bag = tmp_path / "bag"
    writer = Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP)
    writer.open()
    conn = writer.add_connection(
        "/joint_states", "sensor_msgs/msg/JointState", typestore=wire.TYPESTORE
    )
    arm, gripper = wire.joint_state(["j1", "j2"], ""), wire.joint_state(["finger"], "")
    for k in range(1, 6):
        for msg, values in ((arm, [0.1 * k, 0.2 * k]), (gripper, [0.01])):
            msg.header.stamp.nanosec = k * 1_000_000
            msg.position, msg.effort = np.array(values), np.array(values) * 10.0
            msg.velocity = np.zeros(len(values))
            writer.write(conn, k * 1_000_000 + 3 - len(values), wire.encode(msg))  # arm first
    writer.close()
    js = read_joints(bag)
    assert js.names == ("j1", "j2") and js.position.shape == (5, 2)
    np.testing.assert_allclose(js.position[:, 1], 0.2 * np.arange(1, 6))
    assert read_joints(bag, joints=["finger"]).position[:, 0].tolist() == [0.01] * 5
    with pytest.raises(BagError, match="has no joint 'elbow'; joints: j1, j2"):
        read_joints(bag, joints=["j1", "elbow"])
