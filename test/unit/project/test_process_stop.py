"""The tests' own process handling (``support.rosgraph.Process``): a stop leaves nothing behind."""

from __future__ import annotations

import sys
from pathlib import Path

from support.rosgraph import Process
from support.waits import wait_until

#: a launch-like process: deaf to SIGINT, its child in a session of its own and deaf too
LAUNCH = """
import signal, subprocess, sys, time
signal.signal(signal.SIGINT, signal.SIG_IGN)
code = "import signal, time; signal.signal(signal.SIGINT, signal.SIG_IGN); time.sleep(300)"
kid = subprocess.Popen([sys.executable, "-c", code], start_new_session=True)
print(kid.pid, flush=True)
time.sleep(300)
"""


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().split(") ")[1][0] != "Z"
    except (OSError, IndexError):
        return False


def test_a_stop_that_comes_to_killing_kills_what_the_process_started(tmp_path: Path) -> None:
    """A process that ignores SIGINT is killed, and so is the child it started in a session of
    its own (as haptic-launch starts its nodes), by id."""
    log = tmp_path / "launch.log"
    proc = Process([sys.executable, "-c", LAUNCH], {}, log)
    assert wait_until(lambda: log.read_text().strip() != "", 30.0)
    kid = int(log.read_text())
    assert _alive(kid)
    proc.stop(timeout=0.5)
    assert proc.proc.returncode is not None
    assert wait_until(lambda: not _alive(kid), 10.0), f"process {kid} outlived the stop"
