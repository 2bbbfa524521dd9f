"""QoS profiles of the haptic loop.

Loop publishers are reliable and volatile and keep the last 2000 samples: a reliable reader that
falls behind (a recorder on a loaded machine) is repaired from that history, by up to 2000
samples (2 s at 1 kHz), and a reader that joins late (``ros2 topic echo``, a plot, RViz) sees the
live stream at once, not a replay. A reader gets only what is sent after it has matched the
writer, and it can match some time after the writer matched it; so a reader that must have every
sample from the first (the recorder) is matched on both sides before sample 0: the device waits
for its writers to match every subscriber the graph shows, and for every recorder to report that
its readers have matched (``recorder/progress``, ``PROGRESS_NOT_MATCHED_NS`` until then).

The loop's own subscriptions (``loop_input``, a node's ``input_reliability``) have a deep queue.
The command input (the device's ``effort_command``) is reliable by default: a person's one-off
message (``ros2 topic pub --once``) arrives even when it was sent before the reader had matched
the new writer, which a best-effort reader drops. The sensor streams (the environment's and the
controller's inputs) are best effort by default, as ROS 2's sensor-data profile: no
acknowledgements, so nodes in separate processes cycle faster (BENCHMARKS.md measures both); a
sample lost on the critical path of a lockstep run stalls it until the device re-sends the sample
after ``lockstep_timeout_s`` (every node answers a repeated sample idempotently, so the run stays
exact). Nodes sharing a process hand the loop's values over in process either way. The
observer's input is always reliable (``ESTIMATOR_IN``): off the critical path in OL and CL it may
lag on a loaded machine, and a sample lost there would be a permanent gap in the recorded
estimate; reliable delivery repairs it from the publisher's history. The observer counts gaps in
the samples it receives.
"""

from __future__ import annotations

from rclpy.qos import DurabilityPolicy, HistoryPolicy, QoSProfile, ReliabilityPolicy

from haptic_msgs_py.topics import INPUT_RELIABILITY

LOOP_HISTORY = 2000  # samples a loop publisher keeps for late or slow reliable readers
LOOP_IN_DEPTH = 1000  # samples a loop subscription queues (a node off the critical path may lag)

LOOP = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=LOOP_HISTORY,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)

LOOP_IN = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=LOOP_IN_DEPTH,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)

LOOP_IN_BEST_EFFORT = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=LOOP_IN_DEPTH,
    reliability=ReliabilityPolicy.BEST_EFFORT,
    durability=DurabilityPolicy.VOLATILE,
)


def loop_input(reliability: str) -> QoSProfile:
    """The loop subscriptions' profile for ``input_reliability`` (``INPUT_RELIABILITY``)."""
    if reliability not in INPUT_RELIABILITY:
        raise ValueError(
            f"input_reliability must be one of {INPUT_RELIABILITY}, got {reliability!r}"
        )
    return LOOP_IN if reliability == "reliable" else LOOP_IN_BEST_EFFORT


ESTIMATOR_IN = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=LOOP_IN_DEPTH,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)

CLOCK = QoSProfile(history=HistoryPolicy.KEEP_LAST, depth=1, reliability=ReliabilityPolicy.RELIABLE)

RECORD = QoSProfile(
    history=HistoryPolicy.KEEP_LAST,
    depth=LOOP_HISTORY,
    reliability=ReliabilityPolicy.RELIABLE,
    durability=DurabilityPolicy.VOLATILE,
)


def driver(reliability: str, depth: int) -> QoSProfile:
    """A foreign driver's topic as the bridge meets it: keep-last ``depth``, volatile,
    ``reliable`` or ``best_effort`` (a best-effort reader matches both kinds of writer; a
    reliable writer serves both kinds of reader)."""
    kind = (
        ReliabilityPolicy.RELIABLE if reliability == "reliable" else ReliabilityPolicy.BEST_EFFORT
    )
    return QoSProfile(
        history=HistoryPolicy.KEEP_LAST,
        depth=depth,
        reliability=kind,
        durability=DurabilityPolicy.VOLATILE,
    )
