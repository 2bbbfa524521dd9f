"""The Fast DDS profile the suite's processes start with, unless the user gives their own.

A reliable writer repairs a lost sample when a reader answers its heartbeat, which Fast DDS sends
every 3 s by default. Between processes on one machine, samples go through shared-memory ports
of 512 messages; on a loaded machine a reader's port overflows now and then (two recorders beside
the loop on 2 cores), and each loss then stalls that reader, and a lockstep run that waits for
it, for up to 3 s. ``fastdds_profile.xml`` sets the heartbeat to 50 ms: lockstep with two
recorders went from 0.34 to 3.42 times real time (medians, BENCHMARKS.md). It also has
participants announce themselves every 250 ms instead of 3 s: a participant does not always
answer a newcomer's first announcement, and the newcomer then learns of it only at its next
periodic one, so a device waiting for its graph (``wait_for``) waited 2-3 s before sample 0 in
most graph runs, and now about 0.5 s. It changes nothing else (transports, the QoS the nodes set
and the rest of discovery are Fast DDS's and ROS's defaults).
A profile the user names (``FASTRTPS_DEFAULT_PROFILES_FILE``, or ``FASTDDS_DEFAULT_PROFILES_FILE``
of newer Fast DDS) replaces it. Fast DDS also looks for ``DEFAULT_FASTRTPS_PROFILES.xml`` in the
working directory, whose default writer profile may apply instead (not checked here).
"""

from __future__ import annotations

import os
from pathlib import Path

PROFILES_ENV = "FASTRTPS_DEFAULT_PROFILES_FILE"
NEWER_PROFILES_ENV = "FASTDDS_DEFAULT_PROFILES_FILE"  # Fast DDS 3 (ROS 2 Kilted on)
PROFILE = Path(__file__).with_name("fastdds_profile.xml")


def use_default_profile() -> str:
    """Point Fast DDS at ``PROFILE`` unless the user names a profile file (theirs wins); call
    before ``rclpy.init``. Returns the profile file in effect."""
    if NEWER_PROFILES_ENV in os.environ and PROFILES_ENV not in os.environ:
        return os.environ[NEWER_PROFILES_ENV]
    return os.environ.setdefault(PROFILES_ENV, str(PROFILE))
