"""haptic-analyze on bad input: one ``ERROR:`` line naming the problem, exit 2, no traceback."""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.bag.write import write_session_bag
from haptic_dob.cli.analyze import main
from support.bagdata import msd_record, session_params
from support.paths import tool

FS = 1000.0


@pytest.fixture(scope="module")
def good(tmp_path_factory: pytest.TempPathFactory) -> Path:
    x, f, v = msd_record(6.0, FS, 0.5, 2.0, 800.0)
    path = tmp_path_factory.mktemp("good") / "bag"
    write_session_bag(path, x, f, FS, session_params(), velocity=v)
    return path


def error_of(args: list[str], capsys: pytest.CaptureFixture[str]) -> str:
    """Run the CLI; assert exit code 2 and a single ERROR line; return that line."""
    code = main(args)
    out, err = capsys.readouterr()
    assert code == 2, (out, err)
    lines = err.strip().splitlines()
    assert len(lines) == 1, err
    assert lines[0].startswith("ERROR: "), err
    assert "Traceback" not in err
    return lines[0]


def test_missing_path(tmp_path: Path, capsys) -> None:
    p = tmp_path / "nope"
    assert error_of([str(p)], capsys) == f"ERROR: {p}: no such file or directory"


def test_not_a_bag(tmp_path: Path, capsys) -> None:
    text = tmp_path / "notes.txt"
    text.write_text("not a bag\n")
    assert error_of([str(text)], capsys) == (
        f"ERROR: {text} is not a bag (neither a rosbag2 directory, MCAP nor sqlite3)"
    )
    empty_dir = tmp_path / "dir"
    empty_dir.mkdir()
    assert error_of([str(empty_dir)], capsys) == (
        f"ERROR: {empty_dir} is not a bag: a directory without metadata.yaml"
    )


def test_truncated_mcap(good: Path, tmp_path: Path, capsys) -> None:
    bag = tmp_path / "cut"
    shutil.copytree(good, bag)
    (mcap,) = bag.glob("*.mcap")
    data = mcap.read_bytes()
    mcap.write_bytes(data[: len(data) // 2])
    line = error_of([str(bag)], capsys)
    assert line.startswith(f"ERROR: {bag} is truncated or corrupt (")


def test_corrupt_sqlite(tmp_path: Path, capsys) -> None:
    x, f, v = msd_record(6.0, FS, 0.5, 2.0, 800.0)
    bag = tmp_path / "db"
    write_session_bag(bag, x, f, FS, session_params(), velocity=v, storage="sqlite3")
    (db,) = bag.glob("*.db3")
    data = bytearray(db.read_bytes())
    data[4096 : len(data) - 4096] = b"\xa5" * (len(data) - 8192)  # keep the header page
    db.write_bytes(bytes(data))
    line = error_of([str(bag)], capsys)
    assert line.startswith(f"ERROR: {bag} is truncated or corrupt (")


def test_interrupted_recording_without_metadata(good: Path, tmp_path: Path, capsys) -> None:
    bag = tmp_path / "killed"
    shutil.copytree(good, bag)
    (bag / "metadata.yaml").unlink()
    assert error_of([str(bag)], capsys) == (
        f"ERROR: {bag} is truncated or corrupt: the bag directory has no metadata.yaml "
        f"(was the recording killed before it finished? haptic-record --recover {bag} writes "
        "what it holds to a new bag)"
    )


def test_empty_bag(tmp_path: Path, capsys) -> None:
    from rosbags.rosbag2 import StoragePlugin, Writer

    from haptic_msgs_py.wire import TYPESTORE

    bag = tmp_path / "empty"
    with Writer(bag, version=9, storage_plugin=StoragePlugin.MCAP) as w:
        w.add_connection("/ee_pose", "geometry_msgs/msg/PoseStamped", typestore=TYPESTORE)
    assert error_of([str(bag)], capsys) == (
        f"ERROR: {bag} is an empty bag (no messages; topics: /ee_pose "
        "(geometry_msgs/msg/PoseStamped))"
    )


def test_missing_topic_lists_the_topics(good: Path, capsys) -> None:
    line = error_of([str(good), "--force-topic", "hand_force"], capsys)
    assert line == (
        f"ERROR: {good} has no force topic 'hand_force'; topics: /ee_pose "
        "(geometry_msgs/msg/PoseStamped), /ee_twist (geometry_msgs/msg/TwistStamped), "
        "/parameter_events (rcl_interfaces/msg/ParameterEvent), /wrench_measured "
        "(geometry_msgs/msg/WrenchStamped)"
    )


def test_wrong_message_type(good: Path, capsys) -> None:
    assert error_of([str(good), "--force-topic", "ee_pose"], capsys) == (
        f"ERROR: {good}: the force topic /ee_pose is geometry_msgs/msg/PoseStamped; it must be "
        "geometry_msgs/msg/WrenchStamped"
    )
    assert error_of([str(good), "--motion-topic", "parameter_events"], capsys) == (
        f"ERROR: {good}: the motion topic /parameter_events is rcl_interfaces/msg/ParameterEvent;"
        " it must be geometry_msgs/msg/PoseStamped or sensor_msgs/msg/JointState"
    )


def test_segment_too_short_for_the_spectral_settings(tmp_path: Path, capsys) -> None:
    x, f, v = msd_record(2.4, FS, 0.5, 2.0, 800.0)
    bag = tmp_path / "short"
    write_session_bag(bag, x, f, FS, session_params(), velocity=v)
    assert error_of([str(bag)], capsys) == (
        f"ERROR: {bag}: segment too short for the spectral settings: 1.8 s < one 2 s segment "
        "(1.8 s analysed after leaving out 0.6 s)"
    )


def test_no_motion(tmp_path: Path, capsys) -> None:
    n = 10_000
    bag = tmp_path / "still"
    write_session_bag(bag, np.full(n, 2e-3), np.full(n, 1.6), FS, session_params())
    assert error_of([str(bag)], capsys) == (
        f"ERROR: {bag}: no motion: /ee_pose x is constant (8 s analysed after leaving out 2 s)"
    )


def test_no_recorded_stiffness(tmp_path: Path, capsys) -> None:
    x, f, v = msd_record(6.0, FS, 0.5, 2.0, 800.0)
    bag = tmp_path / "noparams"
    write_session_bag(bag, x, f, FS, {}, velocity=v)
    assert error_of([str(bag)], capsys) == (
        f"ERROR: {bag}: no wall stiffness recorded (pass --stiffness) "
        "(4.5 s analysed after leaving out 1.5 s)"
    )
    assert main([str(bag), "--stiffness", "800"]) == 0
    capsys.readouterr()


def test_bad_options(good: Path, capsys) -> None:
    assert error_of([str(good), "--fmax", "-1"], capsys) == "ERROR: fmax_hz must be > 0, got -1"
    assert error_of([str(good), "--vibration-band", "200"], capsys) == (
        "ERROR: --vibration-band must be LO:HI in Hz, got '200'"
    )
    assert error_of([str(good), "--vibration-band", "20:10"], capsys) == (
        "ERROR: the vibration band needs 0 < LO < HI, got 20:10"
    )
    assert error_of([str(good), "--stiffness", "0"], capsys) == (
        "ERROR: stiffness must be > 0 N/m, got 0"
    )
    assert error_of([str(good), "--motion-topic", "ee_pose", "--settle", "nan"], capsys) == (
        "ERROR: settle_s must be >= 0, got nan"
    )


def test_argparse_errors_are_one_line_too(good: Path) -> None:
    out = subprocess.run(
        [tool("haptic-analyze"), str(good), "--axis", "w"],
        capture_output=True,
        text=True,
        timeout=60,
    )
    assert out.returncode == 2
    assert out.stderr.splitlines()[-1].startswith("ERROR: argument --axis: invalid choice: 'w'")
    assert "Traceback" not in out.stderr


def test_the_installed_command_and_script(tmp_path: Path, root: Path) -> None:
    missing = tmp_path / "gone"
    for argv in (
        [tool("haptic-analyze"), str(missing)],
        [tool("python"), str(root / "scripts" / "haptic_analyze.py"), str(missing)],
    ):
        out = subprocess.run(argv, capture_output=True, text=True, timeout=60)
        assert out.returncode == 2
        assert out.stderr == f"ERROR: {missing}: no such file or directory\n"
