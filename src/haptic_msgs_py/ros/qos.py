"""QoS profiles of the haptic loop.

Loop publishers: reliable, volatile, keep last 2000 (a reader that falls behind is repaired by
up to 2000 samples, 2 s at 1 kHz; a late reader sees the live stream, not a replay). A reader
that must have every sample from the first (the recorder) is matched on both sides before
sample 0: the device waits for its writers to match every subscriber the graph shows, and for
every recorder to report its readers matched (``recorder/progress``, ``PROGRESS_NOT_MATCHED_NS``
until then). The loop's subscriptions (``loop_input``, a node's ``input_reliability``) have a
deep queue: the command input (the device's ``effort_command``) reliable by default, the sensor
streams (the environment's and the controller's inputs) best effort by default (a sample lost
on a lockstep run's path is sent again after ``lockstep_timeout_s``), the observer's input
always reliable (``ESTIMATOR_IN``). Nodes sharing a process hand values over in process either
way. Why each: docs/running.md, "Topics"; docs/design/timing.md.
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
