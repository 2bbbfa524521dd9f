"""The recorder's bags are rosbag2 Jazzy bags: ``ros2 bag info`` / ``play`` can read them.

There is no rosbag2 here, so the checks are against what rosbag2 Jazzy reads, taken from its
sources (``support.jazzy_bag``): the metadata, the MCAP records, the sqlite3 tables, the
distribution (``jazzy``) and each topic's offered QoS profiles as ``ros2 bag record`` stores
them and ``ros2 bag play`` offers them again. A killed recording's recovered bag passes the same
checks.

The other way: bags as ``ros2 bag record`` writes them (``ros2bag``: MCAP uncompressed and with
zstd chunks, sqlite3; ``ros2msg`` schemas, receive times, the type hashes) go through
``haptic-analyze`` and ``haptic-identify`` and give what our recording of the same session gives.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import pytest
from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)

from haptic_dob.bag.recover import recover
from haptic_dob.recorder.recording import Recording
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE
from haptic_msgs_py import wire
from haptic_msgs_py.topics import EE_POSE, JOINT_STATES, SESSION_TOPICS
from support.jazzy_bag import check_bag, offered

MS = 1_000_000
N = 1500  # samples per topic: more than one second, so the recorder made the bag durable once

INFINITE = QosTime(9223372036, 854775807)  # rmw's infinite duration, as the graph reports it
# what the graph reports of a publisher (rmw_fastrtps: no history or depth), as qos.cpp writes it
REPORTED_LOOP = {
    "history": "unknown",
    "depth": 0,
    "reliability": "reliable",
    "durability": "volatile",
    "deadline": {"sec": 9223372036, "nsec": 854775807},
    "lifespan": {"sec": 9223372036, "nsec": 854775807},
    "liveliness": "automatic",
    "liveliness_lease_duration": {"sec": 9223372036, "nsec": 854775807},
    "avoid_ros_namespace_conventions": False,
}


def reported(reliability: QosReliability, durability: QosDurability, depth: int = 0) -> Qos:
    history = QosHistory.KEEP_LAST if depth else QosHistory.UNKNOWN
    return Qos(
        history, depth, reliability, durability, INFINITE, INFINITE,
        QosLiveliness.AUTOMATIC, INFINITE, False,
    )  # fmt: skip


#: the publishers of each topic of ``recorded``: the pose has two that differ
OFFERED = {
    "/joint_states": [reported(QosReliability.RELIABLE, QosDurability.VOLATILE)],
    "/ee_pose": [
        reported(QosReliability.BEST_EFFORT, QosDurability.VOLATILE),
        reported(QosReliability.RELIABLE, QosDurability.TRANSIENT_LOCAL, depth=7),
    ],
    "/parameter_events": [],  # none seen
}


def recorded(path: Path, storage: str) -> Path:
    """A bag written the way ``recorder_node`` writes one: joint states and poses at 1 kHz
    stamps, logged at their stamps (each pose comes after the next joint state, so the log times
    go back in the file), a parameter snapshot on ``/parameter_events``, closed with its
    counts; each topic with the QoS profiles its publishers offered (``OFFERED``)."""
    rec = Recording(path, storage, MS, offered=lambda topic: OFFERED[topic])
    on_js = rec.add_topic("/joint_states", SESSION_TOPICS[JOINT_STATES], loop=True)
    on_pose = rec.add_topic("/ee_pose", SESSION_TOPICS[EE_POSE], loop=True)
    rec.add_topic("/parameter_events", PARAMETER_EVENT_TYPE)
    rec.write_snapshot("/controller_node", {"kf": 1.0, "mode": "DOB"}, {"kf": 3, "mode": 4})
    js = wire.joint_state(["slide"], "base_link")
    pose = wire.pose_stamped("base_link")
    for k in range(N + 1):
        for msg, on, stamp in ((js, on_js, k), (pose, on_pose, k - 1)):
            if 0 <= stamp < N:
                msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(stamp * MS, 10**9)
                on(wire.encode(msg))
    rec.close()
    return path


def check_offered(bag: Path, meta: dict[str, Any]) -> None:
    """The offered QoS of ``OFFERED``, as rosbag2 writes it and as rosbags reads it back."""
    from rosbags.rosbag2 import Reader

    got = offered(meta)
    assert got["/joint_states"] == [REPORTED_LOOP]
    assert [q["reliability"] for q in got["/ee_pose"]] == ["best_effort", "reliable"]
    assert [q["durability"] for q in got["/ee_pose"]] == ["volatile", "transient_local"]
    assert [(q["history"], q["depth"]) for q in got["/ee_pose"]] == [
        ("unknown", 0),
        ("keep_last", 7),
    ]
    assert got["/parameter_events"] == []
    with Reader(bag) as reader:
        assert {c.topic: c.ext.offered_qos_profiles for c in reader.connections} == OFFERED


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_the_recorders_bag_is_what_rosbag2_jazzy_reads(tmp_path: Path, storage: str) -> None:
    bag = recorded(tmp_path / "session", storage)
    check_offered(bag, check_bag(bag, storage))


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_recovered_bag_is_what_rosbag2_jazzy_reads(tmp_path: Path, storage: str) -> None:
    bag = recorded(tmp_path / "session", storage)
    (bag / "metadata.yaml").unlink()  # as a kill leaves it (the data itself is complete here)
    got = recover(bag)
    assert got.messages == 2 * N + 1
    check_offered(got.out, check_bag(got.out, storage))


ROS2_BAGS = [("mcap", "none"), ("mcap", "zstd_fast"), ("sqlite3", "none")]
CHANGE_AT = 7000  # a live ros2 param set of the observer's gain, at this sample
ID_KEYS = ("bag",)  # what differs between two bags of one session: their path


def session_bags(
    tmp_path: Path, storage: str, preset: str, declarations: bool = True
) -> tuple[Path, Path]:
    """(ours, theirs): one 12 s OL session with a live change of the observer's gain, written
    by our writer (``write_session_bag``: parameter snapshots, log times from the epoch) and as
    ``ros2 bag record -a`` writes it (``ros2bag``: receive times, the nodes' declarations
    if it was up before them, the change stamped with its sample, /clock, /rosout,
    /diagnostics)."""
    from haptic_dob.bag.write import ParamChange, write_session_bag
    from haptic_dob.core.control import ControlMode, ImpedanceLaw
    from haptic_sim.slide.session import SessionConfig, run_session
    from support.bagdata import session_params
    from support.ros2bag import write_ros2_bag
    from support.ros2bag_session import session_as_recorded

    cfg = SessionConfig.from_yaml(Path(__file__).resolve().parents[2] / "config" / "slide_sim.yaml")
    res = run_session(
        cfg.replace(law=ImpedanceLaw(ControlMode.OL, 0.0, 4.0), loop__duration_s=12.0)
    )
    params = {"device_node": {"clock_mode": "realtime", "seed": 0}, **session_params("OL")}
    changes = [ParamChange(CHANGE_AT, "observer_node", {"gain": 30.0})]
    ours = tmp_path / "ours"
    write_session_bag(
        ours, res.q, res.force_measured, 1000.0, params, changes, res.qd, storage, all_topics=True
    )
    topics, messages = session_as_recorded(
        res.q, res.force_measured, res.qd, 1000.0, params, changes, declarations
    )
    theirs = write_ros2_bag(tmp_path / "theirs", storage, topics, messages, preset)
    return ours, theirs


def cli_json(main: Any, argv: list[str], capsys: pytest.CaptureFixture[str]) -> Any:
    """A command's ``--json`` output, parsed, with the bag's path left out."""
    import json

    assert main([*argv, "--json"]) == 0
    out = json.loads(capsys.readouterr().out)
    for item in out if isinstance(out, list) else [out]:
        for key in ID_KEYS:
            item.pop(key, None)
    return out


@pytest.mark.parametrize(("storage", "preset"), ROS2_BAGS, ids=["mcap", "mcap-zstd", "sqlite3"])
def test_a_bag_as_ros2_bag_record_writes_it_goes_through_every_analysis(
    tmp_path: Path, storage: str, preset: str, capsys: pytest.CaptureFixture[str]
) -> None:
    """``ros2 bag record -a`` started before the session (it has the nodes' declarations):
    haptic-analyze finds the same segments and figures as in our recording of the same session
    (the live change split at its stamp, whatever its receive time), haptic-identify the same
    model."""
    from haptic_dob.cli.analyze import main as analyze
    from haptic_dob.cli.identify import main as identify

    ours, theirs = session_bags(tmp_path, storage, preset)
    check_bag(theirs, storage, in_order=False)  # the fixture holds what rosbag2 Jazzy reads
    if storage == "mcap":
        from mcap.reader import make_reader

        with next(theirs.glob("*.mcap")).open("rb") as fh:
            summary = make_reader(fh).get_summary()
        assert summary is not None
        chunks = {c.compression for c in summary.chunk_indexes}
        assert chunks == ({"zstd"} if preset == "zstd_fast" else {""})
    want = cli_json(analyze, [str(ours)], capsys)
    got = cli_json(analyze, [str(theirs)], capsys)
    assert [s["segment"] for s in got] == [0, 1]
    assert [s["observer_gain"] for s in got] == [41.6, 30.0]
    assert got[1]["start_s"] == CHANGE_AT / 1000.0
    assert got == want
    joints = ["--motion-topic", "joint_states", "--joint", "slide"]
    assert cli_json(analyze, [str(theirs), *joints], capsys) == cli_json(
        analyze, [str(ours), *joints], capsys
    )
    assert cli_json(identify, [str(theirs)], capsys) == cli_json(identify, [str(ours)], capsys)


def test_a_bag_of_ros2_bag_record_started_late_needs_the_stiffness(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Started after the nodes: no declarations, so the wall stiffness comes from
    ``--stiffness``; the live change still splits the session at its stamp."""
    from haptic_dob.cli.analyze import main as analyze

    ours, theirs = session_bags(tmp_path, "mcap", "zstd_fast", declarations=False)
    assert analyze([str(theirs)]) == 2
    assert "no wall stiffness recorded (pass --stiffness)" in capsys.readouterr().err
    want = cli_json(analyze, [str(ours)], capsys)
    got = cli_json(analyze, [str(theirs), "--stiffness", "800"], capsys)
    assert [s["observer_gain"] for s in got] == [None, 30.0]
    for key in ("bandwidth_hz", "impedance_error_pct", "coherence_in_band", "start_s"):
        assert [s[key] for s in got] == [s[key] for s in want], key
