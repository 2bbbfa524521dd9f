"""Console entry points that a Ctrl-C or SIGTERM ends quietly, at any moment of start-up.

``ros2 launch`` and a terminal send SIGINT (then SIGTERM) to a node that may still be importing
numpy, pinocchio and rclpy, or building its nodes, and count anything but exit 0 as a death.
``run_main`` installs a handler for both that leaves at once with status 0 *before* importing the
node's module (``os._exit``: the node does not exist yet, nothing is to be cleaned up, and an
exception raised in the middle of an extension's import would surface as a chained
``ImportError``); the node's runtime (``haptic_dob.runtime.ros.spin.run_nodes``) replaces it
with its clean shutdown (exit 0) once rclpy is initialised. The ``ros2 run`` shims (``ros/lib``)
keep SIGINT ignored from the shell to here, over the interpreter's own start-up. ROS-free and
light: it imports the module only by name. A process ``haptic-launch`` started gets SIGTERM when
the launcher dies (``LAUNCHER_PID``), so a kill -9 or a crash of it stops its nodes in order.
"""

from __future__ import annotations

import ctypes
import importlib
import os
import signal
import sys
from types import FrameType

#: the signals that end a node quietly (exit 0) however early they come
QUIET_SIGNALS = (signal.SIGINT, signal.SIGTERM)

#: one BLAS thread per node process (unless the environment says otherwise): a node's maths are
#: small matrices, and a BLAS pool's workers spin while they wait. Under SCHED_FIFO
#: (``--rt-priority``) a spinning thread keeps its CPU from every thread of its priority, so a
#: solve whose worker cannot run spins for ever: a bridge's start-up did, beside a CPU hog.
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


#: the environment variable through which ``haptic-launch`` gives the processes it starts its
#: pid: each asks for SIGTERM when that process dies (Linux's parent-death signal), so nodes
#: whose launcher was killed (kill -9, a crash) stop in order (a bridge sends its zero) rather
#: than run on unsupervised
LAUNCHER_PID = "HAPTIC_LAUNCHER_PID"
PR_SET_PDEATHSIG = 1  # prctl(2)


def follow_launcher() -> None:
    """SIGTERM to this process when the launcher named in ``LAUNCHER_PID`` dies; leave quietly
    now if it died already. Nothing outside Linux or without the variable (``ros2 run``)."""
    pid = os.environ.pop(LAUNCHER_PID, "")
    if not pid.isdigit() or not sys.platform.startswith("linux"):
        return
    libc = ctypes.CDLL(None, use_errno=True)
    if libc.prctl(PR_SET_PDEATHSIG, int(signal.SIGTERM), 0, 0, 0) != 0:
        return  # not allowed here: the launcher's own stop still stops the node
    if os.getppid() != int(pid):  # the launcher died before the request: nobody supervises
        os._exit(0)


def _leave(_signum: int, _frame: FrameType | None) -> None:
    os._exit(0)  # nothing to clean up yet: the node does not exist; a stop asked for is clean


def run_main(module: str) -> int:
    """Import ``module`` with Ctrl-C/SIGTERM ending the process quietly, one BLAS thread
    (``BLAS_THREADS``) and SIGTERM on the launcher's death (``follow_launcher``), then return
    its ``main()``."""
    for signum in QUIET_SIGNALS:
        signal.signal(signum, _leave)
    follow_launcher()
    for name, value in BLAS_THREADS.items():  # read once, when numpy or scipy loads its BLAS
        os.environ.setdefault(name, value)
    main = importlib.import_module(module).main
    return int(main() or 0)
