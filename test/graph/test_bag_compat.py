"""The recorder's bags are rosbag2 Jazzy bags: ``ros2 bag info`` / ``play`` can read them.

There is no rosbag2 here, so the checks are against what rosbag2 Jazzy reads, taken from its
sources (ros2/rosbag2, branch jazzy): the fields ``rosbag2_storage/yaml.hpp`` decodes from a
version-9 ``metadata.yaml``, what ``rosbag2_storage_mcap/src/mcap_storage.cpp`` reads from an MCAP
file (the ``ros2`` profile, the statistics record, the ``rosbag2`` metadata record, each channel's
``offered_qos_profiles``), read with an independent MCAP reader (``mcap``, Foxglove's, checking
every CRC), and the tables ``rosbag2_storage_sqlite3/src/.../sqlite_storage.cpp`` creates (schema
version 4). A killed recording's recovered bag passes the same checks.

The other way: bags as ``ros2 bag record`` writes them (``ros2bag``: MCAP uncompressed and with
zstd chunks, sqlite3; ``ros2msg`` schemas, receive times, the type hashes) go through
``haptic-analyze`` and ``haptic-identify`` and give what our recording of the same session gives.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path
from typing import Any

import pytest
import yaml

from haptic_dob.bag.recover import recover
from haptic_dob.recorder.recording import Recording
from haptic_dob.recorder.topics import PARAMETER_EVENT_TYPE
from haptic_msgs_py import wire
from haptic_msgs_py.topics import EE_POSE, JOINT_STATES, SESSION_TOPICS

MS = 1_000_000
N = 1500  # samples per topic: more than one second, so the recorder made the bag durable once

# rosbag2 (jazzy) yaml.hpp: convert<BagMetadata>::decode for version 9, and its parts
BAG_FIELDS: dict[str, Any] = {
    "version": int,
    "storage_identifier": str,
    "duration": dict,
    "starting_time": dict,
    "message_count": int,
    "topics_with_message_count": list,
    "relative_file_paths": list,
    "compression_format": str,
    "compression_mode": str,
    "files": list,
    "custom_data": (dict, type(None)),  # an empty map is written as null (~), by rosbag2 too
    "ros_distro": str,
}
TOPIC_FIELDS = {
    "name": str,
    "type": str,
    "serialization_format": str,
    "offered_qos_profiles": list,  # version >= 9: a sequence of QoS maps
    "type_description_hash": str,
}
FILE_FIELDS = {"path": str, "starting_time": dict, "duration": dict, "message_count": int}

# rosbag2 (jazzy) sqlite_storage.cpp: SqliteStorage::initialize, kDBSchemaVersion_ = 4
SQLITE_TABLES = {
    "schema": ["schema_version", "ros_distro"],
    "metadata": ["id", "metadata_version", "metadata"],
    "topics": [
        "id",
        "name",
        "type",
        "serialization_format",
        "offered_qos_profiles",
        "type_description_hash",
    ],
    "message_definitions": [
        "id",
        "topic_type",
        "encoding",
        "encoded_message_definition",
        "type_description_hash",
    ],
    "messages": ["id", "topic_id", "timestamp", "data"],
}


def recorded(path: Path, storage: str) -> Path:
    """A bag written the way ``recorder_node`` writes one: joint states and poses at 1 kHz
    stamps, logged at their stamps (each pose comes after the next joint state, so the log times
    go back in the file), a parameter snapshot on ``/parameter_events``, closed with its
    counts."""
    rec = Recording(path, storage, MS)
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


def check_fields(node: dict[str, Any], fields: dict[str, Any], where: str) -> None:
    for key, kind in fields.items():
        assert key in node, f"{where}: no {key}"
        assert isinstance(node[key], kind), f"{where}.{key}: {node[key]!r} is not {kind}"


def check_metadata(doc: dict[str, Any], storage: str) -> dict[str, Any]:
    """The version-9 bag metadata rosbag2 Jazzy decodes; returns it."""
    meta = doc["rosbag2_bagfile_information"]
    check_fields(meta, BAG_FIELDS, "metadata")
    assert meta["version"] == 9 and meta["storage_identifier"] == storage
    assert "nanoseconds" in meta["duration"]
    assert "nanoseconds_since_epoch" in meta["starting_time"]
    for i, t in enumerate(meta["topics_with_message_count"]):
        check_fields(t["topic_metadata"], TOPIC_FIELDS, f"topics[{i}]")
        assert t["topic_metadata"]["serialization_format"] == "cdr"
        assert isinstance(t["message_count"], int)
    for i, f in enumerate(meta["files"]):
        check_fields(f, FILE_FIELDS, f"files[{i}]")
    assert all(isinstance(v, str) for v in (meta["custom_data"] or {}).values())
    total = sum(t["message_count"] for t in meta["topics_with_message_count"])
    assert meta["message_count"] == total == sum(f["message_count"] for f in meta["files"])
    return meta


def check_mcap(path: Path, meta: dict[str, Any], in_order: bool = True) -> None:
    """What rosbag2's MCAP plugin reads, through an independent reader that checks CRCs;
    ``in_order``: also read every message in log-time order (slow for a large bag)."""
    from mcap.reader import make_reader

    with path.open("rb") as fh:
        reader = make_reader(fh, validate_crcs=True)
        assert reader.get_header().profile == "ros2"
        summary = reader.get_summary()
        assert summary is not None and summary.statistics is not None
        assert summary.statistics.message_count == meta["message_count"]
        schemas = summary.schemas
        for channel in summary.channels.values():
            assert channel.message_encoding == "cdr"
            assert schemas[channel.schema_id].encoding == "ros2msg"
            assert isinstance(yaml.safe_load(channel.metadata["offered_qos_profiles"]), list)
        (record,) = [m for m in reader.iter_metadata() if m.name == "rosbag2"]
        # decoded as a BagMetadata node itself (no rosbag2_bagfile_information key)
        assert yaml.safe_load(record.metadata["serialized_metadata"]) == meta
        times = [m.log_time for _, _, m in reader.iter_messages(log_time_order=in_order)]
    assert len(times) == meta["message_count"]
    assert times == sorted(times) or not in_order


def check_sqlite(path: Path, meta: dict[str, Any]) -> None:
    """The tables and columns rosbag2's sqlite3 plugin creates and reads (schema version 4)."""
    db = sqlite3.connect(f"file:{path}?mode=ro", uri=True)
    try:
        for table, columns in SQLITE_TABLES.items():
            got = [row[1] for row in db.execute(f"PRAGMA table_info({table})")]
            assert got == columns, table
        ((version,),) = db.execute("SELECT schema_version FROM schema").fetchall()
        assert version == 4
        ((meta_version, text),) = db.execute("SELECT metadata_version, metadata FROM metadata")
        assert meta_version == 9 and yaml.safe_load(text) == meta  # a BagMetadata node itself
        for (qos,) in db.execute("SELECT offered_qos_profiles FROM topics"):
            assert isinstance(yaml.safe_load(qos), list)
        ((count,),) = db.execute("SELECT count(*) FROM messages")
        assert count == meta["message_count"]
    finally:
        db.close()


def check_bag(bag: Path, storage: str, in_order: bool = True) -> None:
    meta = check_metadata(yaml.safe_load((bag / "metadata.yaml").read_text()), storage)
    (name,) = meta["relative_file_paths"]
    if storage == "mcap":
        check_mcap(bag / name, meta, in_order)
    else:
        check_sqlite(bag / name, meta)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_the_recorders_bag_is_what_rosbag2_jazzy_reads(tmp_path: Path, storage: str) -> None:
    check_bag(recorded(tmp_path / "session", storage), storage)


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_a_recovered_bag_is_what_rosbag2_jazzy_reads(tmp_path: Path, storage: str) -> None:
    bag = recorded(tmp_path / "session", storage)
    (bag / "metadata.yaml").unlink()  # as a kill leaves it (the data itself is complete here)
    got = recover(bag)
    assert got.messages == 2 * N + 1
    check_bag(got.out, storage)


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
