"""Open a rosbag2 (MCAP or sqlite3) and find its topics; every problem becomes a ``BagError``.

The ``BagError`` names the bag and says what is wrong: missing path, not a bag, truncated or
corrupt, a missing topic (with the topics there are) or a name several topics end with.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import Any

from haptic_dob.bag.errors import BagError
from haptic_dob.teleop.graph import TO_SLAVE
from haptic_msgs_py.wire import TYPESTORE

_MCAP_MAGIC = b"\x89MCAP0\r\n"
_SQLITE_MAGIC = b"SQLite format 3\x00"


def check_bag_path(path: Path, shown: str) -> Path:
    """The path to open (bag directory or storage file); a ``BagError`` says what is wrong."""
    if not path.exists():
        raise BagError(f"{shown}: no such file or directory")
    if path.is_file() and path.name == "metadata.yaml":
        path = path.parent
    if path.is_dir():
        if (path / "metadata.yaml").is_file():
            return path
        if any(path.glob("*.mcap")) or any(path.glob("*.db3")):
            raise BagError(
                f"{shown} is truncated or corrupt: the bag directory has no metadata.yaml "
                "(was the recording killed before it finished? haptic-record --recover "
                f"{shown} writes what it holds to a new bag)"
            )
        raise BagError(f"{shown} is not a bag: a directory without metadata.yaml")
    try:
        with path.open("rb") as fh:
            head = fh.read(16)
    except OSError as exc:
        raise BagError(f"{shown}: cannot read ({exc.strerror})") from None
    if not head:
        raise BagError(f"{shown} is not a bag: the file is empty")
    if not (head.startswith(_MCAP_MAGIC) or head.startswith(_SQLITE_MAGIC)):
        raise BagError(f"{shown} is not a bag (neither a rosbag2 directory, MCAP nor sqlite3)")
    if path.suffix not in (".mcap", ".db3"):
        kind = ".mcap" if head.startswith(_MCAP_MAGIC) else ".db3"
        raise BagError(f"{shown} looks like a {kind} storage file; name it *{kind} to read it")
    return path


def storage_of(path: Path) -> str:
    """``mcap`` or ``sqlite3``: the storage of a path ``check_bag_path`` accepted."""
    if path.is_dir():
        return "mcap" if any(path.glob("*.mcap")) else "sqlite3"
    return "mcap" if path.suffix == ".mcap" else "sqlite3"


def corrupt(shown: str, exc: BaseException) -> BagError:
    """The ``BagError`` of a bag the reader failed on with ``exc``."""
    detail = " ".join(str(exc).split()) or type(exc).__name__
    return BagError(f"{shown} is truncated or corrupt ({detail})")


@contextmanager
def open_bag(path: str | Path) -> Iterator[Any]:
    """An open ``rosbags.highlevel.AnyReader`` of one bag; problems become ``BagError``."""
    # lazy: rosbags.highlevel (ruamel.yaml, rosbag1: ~0.1 s) only once a bag is opened
    from rosbags.highlevel import AnyReader

    shown = str(path)
    p = check_bag_path(Path(path), shown)
    reader = AnyReader([p], default_typestore=TYPESTORE)
    try:
        reader.open()
    except Exception as exc:  # rosbags raises several types for a damaged file
        raise corrupt(shown, exc) from None
    try:
        yield reader
    finally:
        reader.close()


def topics_of(reader: Any) -> dict[str, str]:
    """Topic -> message type of an open reader."""
    return {c.topic: c.msgtype for c in reader.connections}


def listing(topics: dict[str, str]) -> str:
    """``/a (pkg/msg/A), /b (...)`` for error messages."""
    return ", ".join(f"{t} ({ty})" for t, ty in sorted(topics.items())) or "none"


def resolve_topic(topics: dict[str, str], name: str, what: str, shown: str) -> str:
    """The bag topic a (relative or absolute) name means; ``BagError`` if none or several."""
    if name.startswith("/"):
        found = [name] if name in topics else []
    else:
        found = ["/" + name] if "/" + name in topics else []
        if not found:
            found = sorted(t for t in topics if t.endswith("/" + name))
    if not found:
        raise BagError(f"{shown} has no {what} topic {name!r}; topics: {listing(topics)}")
    if len(found) > 1:
        teleop = TO_SLAVE in topics  # both sides' topics: a teleoperation graph's recording
        raise BagError(
            f"{shown} has several {what} topics named {name!r} ({', '.join(found)}); "
            "give the full name"
            + (f" (a recorded teleoperation graph: haptic-teleop --bag {shown})" if teleop else "")
        )
    return found[0]
