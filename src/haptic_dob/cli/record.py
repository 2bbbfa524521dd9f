"""``haptic-record [OUTPUT]``: record a session into a rosbag2 without the ROS 2 command line.

Runs a ``recorder_node`` (``haptic_dob.nodes.recorder_node``) in this process until Ctrl-C,
SIGTERM or ``--duration``, then prints per topic what it received and wrote. The default topics
are every session topic and ``/parameter_events``; a snapshot of every node's parameters in the
namespace goes into the bag too. Start it before the device in lockstep and add its node name to
the device's ``wait_for`` so the run waits for it and nothing is lost.

The recorder puts what it wrote into complete records on disk whenever a topic's stamps advanced
a second of session time; after a kill -9, a crash or a power cut, ``haptic-record --recover
BAG`` writes what is complete (all but at most the last second of session time of each topic) to
a new bag that every tool opens, and says where each topic ends.
"""

from __future__ import annotations

import math
import sys

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.errors import InputError
from haptic_dob.recorder.settings import LOG_TIMES, STORAGES, new_bag_path


def command(
    output: str | None,
    storage: str,
    namespace: str,
    duration: float,
    topics: list[str] | None,
    node_name: str,
    rate_hz: float,
    log_time: str = "session",
) -> int:
    """Check the arguments, record, print the counts; ``InputError``/``ValueError`` on bad input."""
    path = new_bag_path(output or "")
    if not (duration >= 0.0 and math.isfinite(duration)):
        raise InputError(f"--duration must be >= 0 s, got {duration:g}")
    if not (rate_hz > 0.0 and math.isfinite(rate_hz)):
        raise InputError(f"--rate must be > 0 Hz, got {rate_hz:g}")
    if namespace and not namespace.startswith("/"):
        namespace = "/" + namespace
    from haptic_dob.nodes.recorder_run import record  # lazy: rclpy after the arguments are checked

    code, node = record(
        str(path), storage, namespace, duration, topics, node_name, rate_hz, log_time
    )
    if node is not None:
        rec = node.recording
        print(rec.counts.table(rec.path, rec.storage))
    return code


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-record``."""
    p = ArgumentParser(prog="haptic-record", description=__doc__.split("\n\n")[0])
    p.add_argument(
        "output", nargs="?", help="bag directory to create (default haptic_<date>_<time>)"
    )
    p.add_argument("--storage", choices=STORAGES, default="mcap", help="default mcap")
    p.add_argument("--namespace", default="", help="namespace of the session (default none)")
    p.add_argument(
        "--duration",
        type=float,
        default=0.0,
        metavar="S",
        help="stop after this many wall-clock seconds (default: until Ctrl-C/SIGTERM)",
    )
    p.add_argument(
        "--topic",
        action="append",
        dest="topics",
        metavar="TOPIC[:TYPE]",
        help="record this topic (repeatable; default: the session topics and /parameter_events)",
    )
    p.add_argument("--node-name", default="recorder_node", help="node name (default recorder_node)")
    p.add_argument(
        "--rate",
        type=float,
        default=1000.0,
        metavar="HZ",
        help="loop rate, to count missing stamps (default 1000)",
    )
    p.add_argument(
        "--log-time",
        choices=LOG_TIMES,
        default="session",
        help="bag time of each message: the session's (its own stamp, or the newest one; as "
        "ros2 bag record --use-sim-time; default) or the wall-clock receive time",
    )
    p.add_argument(
        "--recover",
        metavar="BAG",
        help="instead of recording: write the complete part of a recording that was killed "
        "(no metadata.yaml) to a new bag, OUTPUT or BAG_recovered",
    )
    a = p.parse_args(argv)
    if a.recover is not None:
        return run(lambda: recover_command(a.recover, a.output))
    return run(
        lambda: command(
            a.output, a.storage, a.namespace, a.duration, a.topics, a.node_name, a.rate, a.log_time
        )
    )


def recover_command(bag: str, output: str | None) -> int:
    """``--recover BAG``: the killed recording's complete records into a new bag."""
    from haptic_dob.bag.recover import recover  # lazy: --help answers before rosbags loads

    print(recover(bag, output).summary())
    return 0


if __name__ == "__main__":
    sys.exit(main())
