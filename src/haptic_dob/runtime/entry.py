"""Console entry points that a Ctrl-C or SIGTERM ends quietly, at any moment of start-up.

``ros2 launch`` and a terminal send SIGINT (then SIGTERM) to a node that may still be importing
numpy, pinocchio and rclpy, or building its nodes, and count anything but exit 0 as a death.
``run_main`` installs a handler for both that leaves at once with status 0 *before* importing the
node's module (``os._exit``: the node does not exist yet, nothing is to be cleaned up, and an
exception raised in the middle of an extension's import would surface as a chained
``ImportError``); the node's runtime (``haptic_dob.runtime.ros.spin.run_nodes``) replaces it
with its clean shutdown (exit 0) once rclpy is initialised. The ``ros2 run`` shims (``ros/lib``)
keep SIGINT ignored from the shell to here, over the interpreter's own start-up. ROS-free and
light: it imports the module only by name.
"""

from __future__ import annotations

import importlib
import os
import signal
from types import FrameType

#: the signals that end a node quietly (exit 0) however early they come
QUIET_SIGNALS = (signal.SIGINT, signal.SIGTERM)

#: one BLAS thread per node process (unless the environment says otherwise): a node's maths are
#: small matrices, and a BLAS pool's workers spin while they wait. Under SCHED_FIFO
#: (``--rt-priority``) a spinning thread keeps its CPU from every thread of its priority, so a
#: solve whose worker cannot run spins for ever: a bridge's start-up did, beside a CPU hog.
BLAS_THREADS = {"OPENBLAS_NUM_THREADS": "1", "OMP_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


def _leave(_signum: int, _frame: FrameType | None) -> None:
    os._exit(0)  # nothing to clean up yet: the node does not exist; a stop asked for is clean


def run_main(module: str) -> int:
    """Import ``module`` with Ctrl-C/SIGTERM ending the process quietly and one BLAS thread
    (``BLAS_THREADS``), then return its ``main()``."""
    for signum in QUIET_SIGNALS:
        signal.signal(signum, _leave)
    for name, value in BLAS_THREADS.items():  # read once, when numpy or scipy loads its BLAS
        os.environ.setdefault(name, value)
    main = importlib.import_module(module).main
    return int(main() or 0)
