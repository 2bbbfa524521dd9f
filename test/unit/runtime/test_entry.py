"""A node executable's entry (``runtime.entry.run_main``): what it sets before the node loads."""

from __future__ import annotations

import os
import subprocess
import sys

from haptic_dob.runtime.entry import BLAS_THREADS

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
