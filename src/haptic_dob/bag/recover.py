"""Recover a bag whose recording was killed (kill -9, a crash, a power cut) before it closed.

A rosbag2 directory gets its ``metadata.yaml`` only when the writer closes; an MCAP file gets its
summary, footer and end magic then too, and a sqlite3 file commits then. The recorder therefore
closes an MCAP chunk (flushed and synced) or commits the sqlite3 transaction whenever a topic's
stamps have advanced a second of session time (``haptic_dob.recorder.recording``), so a killed
recording holds all but at most its last second of each topic in complete records.

``recover`` reads what is complete, without changing the original: for MCAP every record up to the
first incomplete one (a data-end record and a footer are added to a private copy, which rosbags
then reads by scanning), for sqlite3 every committed row (the private copy's journal is rolled
back by sqlite itself). It writes a new, closed bag (same storage, same topics, types and QoS)
that every tool opens, keeping every complete message, and says per topic where its stamps end
(topics written at one moment end at different stamps: docs/recording-and-analysis.md).
"""

from __future__ import annotations

import json
import shutil
import sqlite3
import struct
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.rosbag2 import WriterError
from rosbags.rosbag2.errors import ReaderError
from rosbags.rosbag2.storage_mcap import McapReader
from rosbags.rosbag2.storage_sqlite3 import Sqlite3Reader
from rosbags.typesys import Stores, get_types_from_msg, get_typestore

from haptic_dob.bag.cdr import stamp_reader
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.write import open_writer
from haptic_msgs_py.stamps import NS_PER_S

MCAP_MAGIC = b"\x89MCAP0\r\n"
RECOVERED_KEY = "haptic_dob.recovered"  # custom data of a recovered bag: where it came from
_OP_DATA_END = 0x0F
_OP_FOOTER = 0x02
_RECORD_HEAD = 9  # opcode (1 byte) + record length (uint64)


@dataclass(frozen=True)
class TopicEnd:
    """One recovered topic: its messages and the stamps of its first and last (header stamps or
    command labels; None for a topic that carries none)."""

    topic: str
    messages: int
    first_ns: int | None
    last_ns: int | None

    def line(self) -> str:
        """``<topic>: N messages[, stamps A-B s]``."""
        span = (
            ""
            if self.first_ns is None or self.last_ns is None
            else (f", stamps {self.first_ns / NS_PER_S:.3f}-{self.last_ns / NS_PER_S:.3f} s")
        )
        return f"{self.topic}: {self.messages} messages{span}"


@dataclass(frozen=True)
class Recovery:
    """What ``recover`` found and wrote."""

    source: Path
    out: Path
    storage: str  # "mcap" or "sqlite3"
    messages: int
    topics: int
    duration_s: float  # from the first to the last recovered message
    dropped_bytes: int  # MCAP: the incomplete tail left out (sqlite3: 0)
    ends: tuple[TopicEnd, ...] = ()  # per topic, in the bag's order

    @property
    def common_end_ns(self) -> int | None:
        """The newest stamp every stamped topic reached (ns); None without a stamped topic."""
        lasts = [e.last_ns for e in self.ends if e.last_ns is not None]
        return min(lasts) if lasts else None

    def as_json(self) -> dict[str, Any]:
        """What the recovered bag's metadata says of its origin (custom data ``RECOVERED_KEY``)."""
        return {
            "source": str(self.source),
            "storage": self.storage,
            "messages": self.messages,
            "dropped_bytes": self.dropped_bytes,
            "topics": {
                e.topic: {
                    "messages": e.messages,
                    "first_stamp_ns": e.first_ns,
                    "last_stamp_ns": e.last_ns,
                }
                for e in self.ends
            },
            "common_end_stamp_ns": self.common_end_ns,
        }

    def summary(self) -> str:
        """What was recovered, for the user: a line, a line per topic, where every one ends."""
        tail = f"; left out an incomplete tail of {self.dropped_bytes} bytes" * bool(
            self.dropped_bytes
        )
        lines = [
            f"recovered {self.messages} messages on {self.topics} topics "
            f"({self.duration_s:.3f} s) from {self.source} into {self.out} "
            f"({self.storage}){tail}"
        ]
        lines += [f"  {e.line()}" for e in self.ends]
        common = self.common_end_ns
        if common is not None:
            newest = max(e.last_ns for e in self.ends if e.last_ns is not None)
            lines.append(
                f"every stamped topic reaches {common / NS_PER_S:.3f} s"
                + (f"; after it only some do, up to {newest / NS_PER_S:.3f} s" * (newest > common))
            )
        return "\n".join(lines)


def complete_mcap_prefix(data: bytes | memoryview) -> int:
    """Length (bytes) of the longest prefix of an MCAP file that ends with a complete record
    before any data-end record: a killed writer's file up to its first incomplete record."""
    if bytes(data[:8]) != MCAP_MAGIC:
        raise ValueError("not an MCAP file (no start magic)")
    pos = len(MCAP_MAGIC)
    while pos + _RECORD_HEAD <= len(data):
        op = data[pos]
        (length,) = struct.unpack_from("<Q", data, pos + 1)
        end = pos + _RECORD_HEAD + length
        if op == _OP_DATA_END or end > len(data):
            break
        pos = end
    return pos


def closed_mcap(prefix: bytes | memoryview) -> bytes:
    """``prefix`` (complete records) closed as a valid MCAP file without a summary section."""
    data_end = bytes([_OP_DATA_END]) + struct.pack("<QI", 4, 0)  # data section CRC 0: unchecked
    footer = bytes([_OP_FOOTER]) + struct.pack("<QQQI", 20, 0, 0, 0)  # no summary section
    return bytes(prefix) + data_end + footer + MCAP_MAGIC


def storage_file(bag: Path, shown: str) -> tuple[Path, str]:
    """The one storage file of a bag directory (or the file given) and its storage name."""
    if bag.is_file():
        files = [bag]
    elif bag.is_dir():
        files = sorted(bag.glob("*.mcap")) + sorted(bag.glob("*.db3"))
    else:
        raise BagError(f"{shown}: no such file or directory")
    if not files:
        raise BagError(f"{shown} holds no .mcap or .db3 file: nothing to recover")
    if len(files) > 1:
        raise BagError(f"{shown} holds {len(files)} storage files; recover them one at a time")
    path = files[0]
    if path.suffix == ".mcap":
        return path, "mcap"
    if path.suffix == ".db3":
        return path, "sqlite3"
    raise BagError(f"{shown}: {path.name} is neither .mcap nor .db3")


def _copy_readable(path: Path, storage: str, work: Path) -> tuple[Path, int]:
    """A private copy of the storage file that rosbags' storage reader opens, and the bytes
    left out."""
    if storage == "mcap":
        data = path.read_bytes()
        try:
            end = complete_mcap_prefix(data)
        except ValueError as exc:
            raise BagError(f"{path}: {exc}") from None
        copy = work / path.name
        copy.write_bytes(closed_mcap(memoryview(data)[:end]))
        return copy, len(data) - end
    copy = work / path.name
    for sibling in path.parent.glob(path.name + "*"):  # the file and its -journal / -wal
        shutil.copy2(sibling, work / sibling.name)
    try:  # a read-write open rolls back a hot journal (or replays a WAL), as sqlite does
        with sqlite3.connect(copy) as db:
            db.execute("SELECT count(*) FROM sqlite_master").fetchone()
        db.close()
    except sqlite3.DatabaseError as exc:
        raise BagError(f"{path}: not a readable sqlite3 database ({exc})") from None
    return copy, 0


def _reader(copy: Path, storage: str) -> Any:
    """rosbags' storage-level reader of one file (no metadata.yaml needed)."""
    if storage == "mcap":
        return McapReader(copy)
    return Sqlite3Reader(copy)


def _in_file_order(reader: Any, conns: list[Any], storage: str) -> Any:
    """The messages as written. An MCAP copy without its summary is read by scanning, which
    rosbags' ``messages`` refuses when log times go back (a recorder logging loop messages at
    their own stamps writes them in the order they came); the new bag is indexed again."""
    if storage == "mcap":
        return reader.messages_scan(conns)
    return reader.messages(conns)


def _typestore(conns: list[Any], path: Path) -> Any:
    """Jazzy's typestore, with any type of ``conns`` it lacks read from the bag's definition."""
    typestore = get_typestore(Stores.ROS2_JAZZY)
    for c in conns:
        if c.msgtype not in typestore.fielddefs:
            try:
                typestore.register(get_types_from_msg(c.msgdef.data, c.msgtype))
            except Exception as exc:  # rosbags raises several kinds on a foreign definition
                raise BagError(f"{path}: cannot read the type {c.msgtype} ({exc})") from None
    return typestore


class _Span:
    """The messages of one topic and the span of their stamps, as they are read."""

    def __init__(self, stamp_of: Callable[[bytes], int | None] | None) -> None:
        self.stamp_of = stamp_of
        self.messages = 0
        self.first: int | None = None
        self.last: int | None = None

    def add(self, data: bytes) -> None:
        self.messages += 1
        stamp = None if self.stamp_of is None else self.stamp_of(data)
        if stamp is not None:
            self.first = stamp if self.first is None else min(self.first, stamp)
            self.last = stamp if self.last is None else max(self.last, stamp)

    def end(self, topic: str) -> TopicEnd:
        return TopicEnd(topic, self.messages, self.first, self.last)


def recover(bag: str | Path, out: str | Path | None = None) -> Recovery:
    """Write the complete part of the killed recording ``bag`` to a new bag ``out`` (default:
    ``<bag>_recovered``). Raises ``BagError`` (one line) when there is nothing to recover."""
    bag = Path(bag)
    if (bag / "metadata.yaml").is_file():
        raise BagError(f"{bag} has its metadata.yaml: it was closed, there is nothing to recover")
    path, storage = storage_file(bag, str(bag))
    target = Path(out) if out is not None else bag.with_name(bag.name + "_recovered")
    if target.exists():
        raise BagError(f"{target} exists; give another output path or remove it")
    with tempfile.TemporaryDirectory(prefix="haptic-recover-") as tmp:
        copy, dropped = _copy_readable(path, storage, Path(tmp))
        reader = _reader(copy, storage)
        try:
            reader.open()
        except (ReaderError, OSError, ValueError, AssertionError) as exc:
            raise BagError(f"{path}: nothing readable to recover ({exc})") from None
        try:
            conns = list(reader.connections)
            if not conns:
                raise BagError(f"{path}: no complete topic record (killed in its first second?)")
            try:
                writer = open_writer(target, storage)
            except (WriterError, OSError) as exc:
                raise BagError(f"{target}: cannot create the recovered bag ({exc})") from None
            typestore = _typestore(conns, path)
            added = {
                c.id: writer.add_connection(
                    c.topic,
                    c.msgtype,
                    typestore=typestore,
                    serialization_format=c.ext.serialization_format,
                    offered_qos_profiles=c.ext.offered_qos_profiles,
                )
                for c in conns
            }
            ends = {
                c.id: _Span(stamp_reader(c.topic, c.msgtype, typestore.fielddefs)) for c in conns
            }
            count, first, last = 0, None, None
            for conn, stamp, data in _in_file_order(reader, conns, storage):
                writer.write(added[conn.id], stamp, data)
                ends[conn.id].add(data)
                count += 1
                first = stamp if first is None else min(first, stamp)
                last = stamp if last is None else max(last, stamp)
            span = (last - first) * 1e-9 if first is not None and last is not None else 0.0
            topics = tuple(ends[c.id].end(c.topic) for c in conns)
            got = Recovery(bag, target, storage, count, len(conns), span, dropped, topics)
            writer.set_custom_data(RECOVERED_KEY, json.dumps(got.as_json()))
            writer.close()
        finally:
            reader.close()
    return got
