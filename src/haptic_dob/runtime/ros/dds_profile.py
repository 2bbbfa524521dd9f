"""The Fast DDS profile the suite's processes start with, unless the user gives their own.

``fastdds_profile.xml`` sets reliable writers' heartbeat period to 50 ms and participants'
announcement period to 250 ms (Fast DDS's defaults: 3 s each); transports, the QoS the nodes set
and the rest of discovery stay Fast DDS's and ROS's defaults. A profile the user names
(``FASTRTPS_DEFAULT_PROFILES_FILE``, or ``FASTDDS_DEFAULT_PROFILES_FILE`` of newer Fast DDS)
replaces it. Fast DDS also looks for ``DEFAULT_FASTRTPS_PROFILES.xml`` in the working directory,
whose default writer profile may apply instead (not checked here). Why the two periods and what
they changed: docs/running.md, "The Fast DDS profile" (Topics), and BENCHMARKS.md.
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
