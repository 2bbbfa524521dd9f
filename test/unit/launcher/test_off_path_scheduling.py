"""Under ``haptic-launch --rt-priority`` a process off the command's path (a recorder alone)
starts at normal scheduling: ``supervise.off_path_scheduling``."""

from __future__ import annotations

import os
import subprocess
import sys

import pytest

from support.paths import can_use_fifo

#: in a process of its own, so that this test's worker keeps its scheduling: the launch's own
#: policy before and under SCHED_FIFO, and what a child started each way runs under
SCRIPT = """
import os, subprocess, sys
from haptic_dob.launcher.supervise import off_path_scheduling
print(off_path_scheduling() is None)
os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(10))
probe = [sys.executable, "-c", "import os; print(os.sched_getscheduler(0))"]
for start in (None, off_path_scheduling()):
    print(subprocess.run(probe, preexec_fn=start, capture_output=True, text=True).stdout.strip())
"""


@pytest.mark.skipif(not can_use_fifo(10), reason="SCHED_FIFO is not allowed here")
def test_a_process_off_the_path_leaves_the_launchs_real_time_scheduling() -> None:
    out = subprocess.run([sys.executable, "-c", SCRIPT], capture_output=True, text=True, timeout=60)
    assert out.returncode == 0, out.stderr
    assert out.stdout.split() == ["True", str(os.SCHED_FIFO), str(os.SCHED_OTHER)]
