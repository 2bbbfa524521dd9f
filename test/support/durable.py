"""What a kill -9 of a recorder would leave, watched from outside while it records; a CPU hog.

``DurableEnd`` reads, as the bag grows, the newest log time in complete records on disk: for
MCAP the newest chunk's end time among the complete records (what ``haptic-record --recover``
keeps), for sqlite3 the newest committed row's time. A test uses it to kill a recorder when the
most of what it wrote is not yet durable, the moment that tests the durability bound.
"""

from __future__ import annotations

import contextlib
import os
import sqlite3
import struct
import subprocess
import sys
from collections.abc import Iterator
from pathlib import Path

_HEAD = 9  # an MCAP record's opcode (1 byte) and length (uint64)
_CHUNK = 0x06


class DurableEnd:
    """The newest log time (ns) in complete records of the bag directory ``bag`` (``storage``
    mcap or sqlite3) so far; ``poll`` reads what was added since the last call."""

    def __init__(self, bag: Path, storage: str) -> None:
        self.bag = bag
        self.storage = storage
        self.newest_ns = -1
        self._offset = 8  # after the MCAP start magic

    def poll(self) -> int:
        """The newest durable log time (ns; -1 before any), read now."""
        files = sorted(self.bag.glob("*.mcap" if self.storage == "mcap" else "*.db3"))
        if not files:
            return self.newest_ns
        if self.storage == "mcap":
            self._scan_mcap(files[0])
        else:
            self._query_sqlite(files[0])
        return self.newest_ns

    def _scan_mcap(self, path: Path) -> None:
        with path.open("rb") as fh:
            fh.seek(self._offset)
            data = fh.read()
        pos = 0
        while pos + _HEAD <= len(data):
            op = data[pos]
            (length,) = struct.unpack_from("<Q", data, pos + 1)
            if pos + _HEAD + length > len(data):
                break
            if op == _CHUNK and length >= 16:
                (end,) = struct.unpack_from("<Q", data, pos + _HEAD + 8)  # message_end_time
                self.newest_ns = max(self.newest_ns, end)
            pos += _HEAD + length
        self._offset += pos

    def _query_sqlite(self, path: Path) -> None:
        try:  # the writer's lock may keep a reader out a moment: ask again at the next poll
            db = sqlite3.connect(f"file:{path}?mode=ro", uri=True, timeout=0.01)
            try:
                (row,) = db.execute("SELECT max(timestamp) FROM messages").fetchall()
            finally:
                db.close()
        except sqlite3.OperationalError:
            return
        if row[0] is not None:
            self.newest_ns = max(self.newest_ns, int(row[0]))


@contextlib.contextmanager
def cpu_hogs(count: int | None = None) -> Iterator[list[int]]:
    """``count`` busy Python processes (default: one per CPU this process may use) while the
    block runs; their pids. Each is killed by its pid at the end."""
    n = len(os.sched_getaffinity(0)) if count is None else count
    procs = [
        subprocess.Popen([sys.executable, "-c", "while 1: pass"], stdin=subprocess.DEVNULL)
        for _ in range(n)
    ]
    try:
        yield [p.pid for p in procs]
    finally:
        for p in procs:
            p.kill()
            p.wait(5)
