"""Bags as rosbag2 Jazzy's ``ros2 bag record`` writes them, for tests (no rosbag2 runs here).

From rosbag2's sources (ros2/rosbag2, branch jazzy):

- MCAP (``mcap_storage.cpp``): the ``ros2`` profile, 768 KiB chunks without CRCs, uncompressed
  or zstd (``zstd_fast``); a schema per type (``ros2msg``, the full text rosbag2 builds from the
  ``.msg`` files); a channel per topic (``cdr``) with ``offered_qos_profiles`` and
  ``topic_type_hash``; log time = receive time, publish time = send time; the ``rosbag2``
  metadata record at close. Written with Foxglove's ``mcap`` writer.
- sqlite3 (``sqlite_storage.cpp``): schema version 4's ``CREATE`` statements, a
  ``message_definitions`` row per type, the metadata row at close.
- ``metadata.yaml`` (``metadata_io.cpp``, ``qos.cpp``): version 9, QoS profiles as maps, the
  types' RIHS01 hashes, ``custom_data: ~``, ``ros_distro: jazzy``; storage ``<bag>_0.mcap`` or
  ``<bag>_0.db3``."""

from __future__ import annotations

import json
import re
import sqlite3
import sys
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import yaml

#: rmw's infinite duration (RMW_DURATION_INFINITE), as endpoint QoS reports an unset deadline
INFINITE = {"sec": 9223372036, "nsec": 854775807}
SEPARATOR = "=" * 80 + "\n"
#: local_message_definition_source.cpp: field types of a .msg and the primitive ones
_FIELD_TYPE = re.compile(r"(?:^|\n)\s*([a-zA-Z0-9_/]+)(?:\[[^\]]*\])?\s+")
_PRIMITIVES = {
    "bool",
    "byte",
    "char",
    "float32",
    "float64",
    "int8",
    "uint8",
    "int16",
    "uint16",
    "int32",
    "uint32",
    "int64",
    "uint64",
    "string",
}
#: sqlite_storage.cpp, SqliteStorage::initialize (schema version 4)
SQLITE_SCHEMA = (
    "CREATE TABLE schema(schema_version INTEGER PRIMARY KEY,ros_distro TEXT NOT NULL);",
    "CREATE TABLE metadata(id INTEGER PRIMARY KEY,metadata_version INTEGER NOT NULL,"
    "metadata TEXT NOT NULL);",
    "CREATE TABLE topics(id INTEGER PRIMARY KEY,name TEXT NOT NULL,type TEXT NOT NULL,"
    "serialization_format TEXT NOT NULL,offered_qos_profiles TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);",
    "CREATE TABLE message_definitions(id INTEGER PRIMARY KEY,topic_type TEXT NOT NULL,"
    "encoding TEXT NOT NULL,encoded_message_definition TEXT NOT NULL,"
    "type_description_hash TEXT NOT NULL);",
    "CREATE TABLE messages(id INTEGER PRIMARY KEY,topic_id INTEGER NOT NULL,"
    "timestamp INTEGER NOT NULL, data BLOB NOT NULL);",
    "CREATE INDEX timestamp_idx ON messages (timestamp ASC);",
)


@dataclass(frozen=True)
class Topic:
    """A recorded topic: its type and the QoS profiles its publishers offered."""

    name: str
    typename: str
    offered_qos: tuple[dict[str, Any], ...]


@dataclass(frozen=True)
class Received:
    """One message as the recorder got it: receive and send (source) time, CDR bytes."""

    topic: str
    recv_ns: int
    send_ns: int
    data: bytes


def qos(depth: int, reliability: str = "reliable", durability: str = "volatile") -> dict[str, Any]:
    """An offered QoS profile as ``qos.cpp`` encodes it for version 9."""
    return {
        "history": "keep_last",
        "depth": depth,
        "reliability": reliability,
        "durability": durability,
        "deadline": dict(INFINITE),
        "lifespan": dict(INFINITE),
        "liveliness": "automatic",
        "liveliness_lease_duration": dict(INFINITE),
        "avoid_ros_namespace_conventions": False,
    }


def _share(typename: str) -> Path:
    """The installed ``share/<pkg>/msg/<Name>`` of ``pkg/msg/Name`` or ``pkg/Name`` (no suffix)."""
    parts = typename.split("/")
    return Path(sys.prefix) / "share" / parts[0] / "msg" / parts[-1]


def message_definition(typename: str) -> str:
    """The ``ros2msg`` full text rosbag2 stores for ``typename``: its ``.msg`` file, then each
    dependency (sorted, first seen only, depth first) after a separator line and ``MSG: <type>``."""
    seen: set[str] = set()

    def text_of(name: str) -> str:
        text = _share(name).with_suffix(".msg").read_text()
        package = name.split("/")[0]
        deps = set()
        for m in _FIELD_TYPE.finditer(text):
            field = m.group(1)
            if field not in _PRIMITIVES:
                deps.add(field if "/" in field else f"{package}/{field}")
        for dep in sorted(deps):
            if dep not in seen:
                seen.add(dep)
                text += "\n" + SEPARATOR + f"MSG: {dep}\n" + text_of(dep)
        return text

    return text_of(typename)


def type_hash(typename: str) -> str:
    """The type description hash (RIHS01) of the installed type, as its publishers report it."""
    doc = json.loads(_share(typename).with_suffix(".json").read_text())
    (own,) = [h["hash_string"] for h in doc["type_hashes"] if h["type_name"] == typename]
    return str(own)


def _dump(node: Any) -> str:
    """Block-style YAML, keys in order (as yaml-cpp emits them)."""
    return yaml.safe_dump(node, sort_keys=False, default_flow_style=False)


def bag_metadata(
    storage: str, file_name: str, topics: Sequence[Topic], messages: Sequence[Received]
) -> dict[str, Any]:
    """``BagMetadata`` version 9 as ``yaml.hpp`` encodes it."""
    start = min(m.recv_ns for m in messages)
    span = {"nanoseconds": max(m.recv_ns for m in messages) - start}
    counts = {t.name: 0 for t in topics}
    for m in messages:
        counts[m.topic] += 1
    return {
        "version": 9,
        "storage_identifier": storage,
        "duration": span,
        "starting_time": {"nanoseconds_since_epoch": start},
        "message_count": len(messages),
        "topics_with_message_count": [
            {
                "topic_metadata": {
                    "name": t.name,
                    "type": t.typename,
                    "serialization_format": "cdr",
                    "offered_qos_profiles": list(t.offered_qos),
                    "type_description_hash": type_hash(t.typename),
                },
                "message_count": counts[t.name],
            }
            for t in topics
        ],
        "compression_format": "",
        "compression_mode": "",
        "relative_file_paths": [file_name],
        "files": [
            {
                "path": file_name,
                "starting_time": {"nanoseconds_since_epoch": start},
                "duration": span,
                "message_count": len(messages),
            }
        ],
        "custom_data": None,
        "ros_distro": "jazzy",
    }


def write_ros2_bag(
    path: Path,
    storage: str,
    topics: Sequence[Topic],
    messages: Sequence[Received],
    preset: str = "none",
) -> Path:
    """A new bag directory ``path`` holding ``messages`` in the order they were received, as
    ``ros2 bag record -s <storage> [--storage-preset-profile <preset>]`` writes it."""
    path.mkdir()
    name = f"{path.name}_0.{'mcap' if storage == 'mcap' else 'db3'}"
    came = sorted(messages, key=lambda m: m.recv_ns)
    meta = bag_metadata(storage, name, topics, came)
    if storage == "mcap":
        _write_mcap(path / name, topics, came, meta, preset)
    else:
        _write_sqlite(path / name, topics, came, meta)
    (path / "metadata.yaml").write_text(_dump({"rosbag2_bagfile_information": meta}))
    return path


def _write_mcap(
    file: Path,
    topics: Sequence[Topic],
    messages: Sequence[Received],
    meta: Mapping[str, Any],
    preset: str,
) -> None:
    from mcap.writer import CompressionType, Writer

    compression = {"none": CompressionType.NONE, "zstd_fast": CompressionType.ZSTD}[preset]
    with file.open("wb") as fh:
        writer = Writer(fh, chunk_size=768 * 1024, compression=compression, enable_crcs=False)
        writer.start(profile="ros2", library="libmcap 1.4.0")
        schemas: dict[str, int] = {}
        channels: dict[str, int] = {}
        for t in topics:
            if t.typename not in schemas:
                schemas[t.typename] = writer.register_schema(
                    t.typename, "ros2msg", message_definition(t.typename).encode()
                )
            channels[t.name] = writer.register_channel(
                t.name,
                "cdr",
                schemas[t.typename],
                {
                    "offered_qos_profiles": _dump(list(t.offered_qos)),
                    "topic_type_hash": type_hash(t.typename),
                },
            )
        for m in messages:
            writer.add_message(channels[m.topic], m.recv_ns, m.data, m.send_ns, sequence=0)
        writer.add_metadata("rosbag2", {"serialized_metadata": _dump(dict(meta))})
        writer.finish()


def _write_sqlite(
    file: Path, topics: Sequence[Topic], messages: Sequence[Received], meta: Mapping[str, Any]
) -> None:
    db = sqlite3.connect(file)
    try:
        for statement in SQLITE_SCHEMA:
            db.execute(statement)
        db.execute("INSERT INTO schema (schema_version, ros_distro) VALUES (?, ?)", (4, "jazzy"))
        ids: dict[str, int] = {}
        defined: set[str] = set()
        for t in topics:
            cur = db.execute(
                "INSERT INTO topics(name, type, serialization_format, offered_qos_profiles, "
                "type_description_hash) VALUES (?, ?, ?, ?, ?)",
                (t.name, t.typename, "cdr", _dump(list(t.offered_qos)), type_hash(t.typename)),
            )
            ids[t.name] = int(cur.lastrowid or 0)
            if t.typename not in defined:
                defined.add(t.typename)
                db.execute(
                    "INSERT INTO message_definitions (topic_type, encoding, "
                    "encoded_message_definition, type_description_hash) VALUES (?, ?, ?, ?)",
                    (t.typename, "ros2msg", message_definition(t.typename), type_hash(t.typename)),
                )
        db.executemany(
            "INSERT INTO messages (timestamp, topic_id, data) VALUES (?, ?, ?);",
            ((m.recv_ns, ids[m.topic], m.data) for m in messages),
        )
        db.execute(
            "INSERT INTO metadata (metadata_version, metadata) VALUES (?, ?)",
            (9, _dump(dict(meta))),
        )
        db.commit()
    finally:
        db.close()
