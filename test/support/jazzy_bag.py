"""What rosbag2 Jazzy reads from a bag, checked field by field (no rosbag2 runs here).

Taken from rosbag2's sources (ros2/rosbag2, branch jazzy): the fields ``rosbag2_storage/yaml.hpp``
decodes from a version-9 ``metadata.yaml`` (each topic's offered QoS profiles as ``qos.cpp``
encodes them for version 9: a map per profile, the policies by rmw's names), what
``rosbag2_storage_mcap/src/mcap_storage.cpp`` reads from an MCAP file (the ``ros2`` profile, the
statistics record, the ``rosbag2`` metadata record, each channel's ``offered_qos_profiles``),
read with an independent MCAP reader (``mcap``, Foxglove's, checking every CRC), and the tables
``rosbag2_storage_sqlite3/src/.../sqlite_storage.cpp`` creates (schema version 4). Every bag
names ``jazzy`` as its ROS distribution.
"""

from __future__ import annotations

import sqlite3
from pathlib import Path
from typing import Any

import yaml

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
# rosbag2_storage (jazzy) qos.cpp: convert<rclcpp::QoS>::encode for version 9, the policies by
# rmw's names (qos_string_conversions.c), an unknown one as "unknown"
QOS_FIELDS = {
    "history": str,
    "depth": int,
    "reliability": str,
    "durability": str,
    "deadline": dict,
    "lifespan": dict,
    "liveliness": str,
    "liveliness_lease_duration": dict,
    "avoid_ros_namespace_conventions": bool,
}
POLICY_NAMES = {
    "history": {"system_default", "keep_last", "keep_all", "unknown"},
    "reliability": {"system_default", "reliable", "best_effort", "best_available", "unknown"},
    "durability": {"system_default", "transient_local", "volatile", "best_available", "unknown"},
    "liveliness": {"system_default", "automatic", "manual_by_topic", "best_available", "unknown"},
}

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
    assert meta["ros_distro"] == "jazzy"
    for i, t in enumerate(meta["topics_with_message_count"]):
        check_fields(t["topic_metadata"], TOPIC_FIELDS, f"topics[{i}]")
        assert t["topic_metadata"]["serialization_format"] == "cdr"
        assert isinstance(t["message_count"], int)
        for j, qos in enumerate(t["topic_metadata"]["offered_qos_profiles"]):
            where = f"topics[{i}].offered_qos_profiles[{j}]"
            check_fields(qos, QOS_FIELDS, where)
            assert set(qos) == set(QOS_FIELDS), where
            for policy, names in POLICY_NAMES.items():
                assert qos[policy] in names, f"{where}.{policy}: {qos[policy]!r}"
            for duration in ("deadline", "lifespan", "liveliness_lease_duration"):
                assert set(qos[duration]) == {"sec", "nsec"}, f"{where}.{duration}"
    for i, f in enumerate(meta["files"]):
        check_fields(f, FILE_FIELDS, f"files[{i}]")
    assert all(isinstance(v, str) for v in (meta["custom_data"] or {}).values())
    total = sum(t["message_count"] for t in meta["topics_with_message_count"])
    assert meta["message_count"] == total == sum(f["message_count"] for f in meta["files"])
    return meta


def offered(meta: dict[str, Any]) -> dict[str, list[dict[str, Any]]]:
    """Each topic's offered QoS profiles in the metadata (what ``ros2 bag play`` offers again)."""
    return {
        t["topic_metadata"]["name"]: t["topic_metadata"]["offered_qos_profiles"]
        for t in meta["topics_with_message_count"]
    }


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
            qos = yaml.safe_load(channel.metadata["offered_qos_profiles"])
            assert (qos or []) == offered(meta)[channel.topic]  # empty text: no profile
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
        ((version, distro),) = db.execute("SELECT schema_version, ros_distro FROM schema")
        assert version == 4 and distro == meta["ros_distro"]
        ((meta_version, text),) = db.execute("SELECT metadata_version, metadata FROM metadata")
        assert meta_version == 9 and yaml.safe_load(text) == meta  # a BagMetadata node itself
        for name, qos in db.execute("SELECT name, offered_qos_profiles FROM topics"):
            assert (yaml.safe_load(qos) or []) == offered(meta)[name]
        ((count,),) = db.execute("SELECT count(*) FROM messages")
        assert count == meta["message_count"]
    finally:
        db.close()


def check_bag(bag: Path, storage: str, in_order: bool = True) -> dict[str, Any]:
    """Every check above; returns the metadata."""
    meta = check_metadata(yaml.safe_load((bag / "metadata.yaml").read_text()), storage)
    (name,) = meta["relative_file_paths"]
    if storage == "mcap":
        check_mcap(bag / name, meta, in_order)
    else:
        check_sqlite(bag / name, meta)
    return meta
