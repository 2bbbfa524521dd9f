"""A node executable's entry (``runtime.entry.run_main``): what it sets before the node loads."""

from __future__ import annotations

import os
import signal
import subprocess
import sys

import pytest

from haptic_dob.runtime.entry import BLAS_THREADS, LAUNCHER_PID
from support.rosgraph import alive
from support.waits import wait_until

PROBE = """
import os, sys, types
probe = types.ModuleType("probe")
def main():
    import numpy as np
    from scipy import linalg
    linalg.solve_discrete_are(np.eye(3), np.eye(3), np.eye(3), np.eye(3))
    print(os.environ.get("OPENBLAS_NUM_THREADS"), len(os.listdir("/proc/self/task")))
    return 0
probe.main = main
sys.modules["probe"] = probe
from haptic_dob.runtime.entry import run_main
sys.exit(run_main("probe"))
"""


def _probe(env: dict[str, str]) -> tuple[str, int]:
    out = subprocess.run(
        [sys.executable, "-c", PROBE], env=env, capture_output=True, text=True, timeout=120
    )
    assert out.returncode == 0, out.stderr
    value, threads = out.stdout.split()
    return value, int(threads)


def test_a_node_loads_numpy_and_scipy_with_one_blas_thread() -> None:
    """No BLAS worker threads in a node's process: numpy's and scipy's would otherwise start one
    per further CPU, which spin while they wait (on one CPU they start none either way)."""
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREADS}
    assert _probe(env) == ("1", 1)


def test_a_blas_thread_count_given_in_the_environment_is_kept() -> None:
    env = {k: v for k, v in os.environ.items() if k not in BLAS_THREADS}
    assert _probe({**env, "OPENBLAS_NUM_THREADS": "2"})[0] == "2"


#: a node that waits: run through ``run_main`` with the launcher's pid in its environment
SLEEPER = """
import sys, time, types
sleeper = types.ModuleType("sleeper")
def main():
    print("running", flush=True)
    time.sleep(60)
    return 3
sleeper.main = main
sys.modules["sleeper"] = sleeper
from haptic_dob.runtime.entry import run_main
sys.exit(run_main("sleeper"))
"""

#: a launcher that starts the sleeper, says its pid, and waits to be killed
LAUNCHER = f"""
import os, subprocess, sys, time
env = {{**os.environ, {LAUNCHER_PID!r}: str(os.getpid())}}
child = subprocess.Popen([sys.executable, "-c", {SLEEPER!r}], env=env, stdout=subprocess.PIPE)
assert child.stdout.readline().strip() == b"running"
print(child.pid, flush=True)
time.sleep(60)
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a Linux parent-death signal")
def test_a_node_whose_launcher_is_killed_gets_sigterm() -> None:
    """kill -9 of the launcher: its node is not left running unsupervised (it gets SIGTERM,
    which a node's runtime answers with its orderly stop; here, before one, a quiet exit)."""
    launcher = subprocess.Popen([sys.executable, "-c", LAUNCHER], stdout=subprocess.PIPE, text=True)
    node = -1
    try:
        assert launcher.stdout is not None
        node = int(launcher.stdout.readline())
        assert alive(node)
        launcher.kill()
        launcher.wait(30)
        assert wait_until(lambda: not alive(node), 30), "the node outlived its launcher"
    finally:
        if launcher.poll() is None:
            launcher.kill()
        if node > 0 and alive(node):
            os.kill(node, signal.SIGKILL)


def test_a_node_whose_launcher_is_gone_already_leaves_without_starting() -> None:
    env = {**os.environ, LAUNCHER_PID: "1"}  # not its parent: the launcher died before
    out = subprocess.run(
        [sys.executable, "-c", SLEEPER], env=env, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0 and "running" not in out.stdout, (out.stdout, out.stderr)
    plain = {k: v for k, v in os.environ.items() if k != LAUNCHER_PID}  # ros2 run: no launcher
    started = subprocess.Popen([sys.executable, "-c", SLEEPER], env=plain, stdout=subprocess.PIPE)
    try:
        assert started.stdout is not None and started.stdout.readline().strip() == b"running"
    finally:
        started.kill()
        started.wait(30)
