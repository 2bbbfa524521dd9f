"""Console entry points that a Ctrl-C during start-up ends quietly.

``ros2 launch`` and a terminal send SIGINT to a node that may still be importing numpy,
pinocchio and rclpy; Python would print a ``KeyboardInterrupt`` traceback. ``run_main`` installs
a SIGINT handler that leaves at once with status 130 (128 + SIGINT) *before* importing the node's
module (``os._exit``: an exception raised in the middle of an extension's import would surface as
a chained ``ImportError``); the node's runtime (``haptic_dob.runtime.ros.spin.run_nodes``)
replaces it with its clean shutdown once the node is up. The ``ros2 run`` shims (``ros/lib``)
keep SIGINT ignored from the shell to here, over the interpreter's own start-up. ROS-free and
light: it imports the module only by name.
"""

from __future__ import annotations

import importlib
import os
import signal
from types import FrameType


def _leave(signum: int, _frame: FrameType | None) -> None:
    os._exit(128 + signum)  # nothing to clean up yet: the node does not exist


def run_main(module: str) -> int:
    """Import ``module`` with Ctrl-C ending the process quietly, then return its ``main()``."""
    signal.signal(signal.SIGINT, _leave)
    main = importlib.import_module(module).main
    return int(main() or 0)
