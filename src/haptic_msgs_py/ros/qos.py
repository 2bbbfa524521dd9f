"""QoS profiles of the haptic loop.

Loop publishers are reliable and transient-local and keep the last 2000 samples: a recorder
(which must not lose a sample) subscribing reliable + transient-local gets every sample even when
its subscription matched a publisher late after start-up (endpoint matching between processes
takes a moment, and a reader can match a writer some time after the writer matched it) or fell
behind, by up to 2000 samples (2 s at 1 kHz). The price: a late reader that asks for the
publisher's durability (``ros2 topic echo`` adapts to it) is first sent that history. Volatile
publishers would spare it, but then a recorder whose reader matched a writer after that writer
had matched it (and sent) loses those samples; the device's start gate sees only its own side of
a match, so that needs a handshake from the reader first.

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
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
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
    durability=DurabilityPolicy.TRANSIENT_LOCAL,
)
