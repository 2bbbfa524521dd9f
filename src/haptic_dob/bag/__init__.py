"""Recorded sessions: read rosbag2 bags (MCAP, sqlite3) and analyse them segment by segment.

ROS-free (``rosbags`` reads and writes the bags): ``read_bag`` streams the motion, hand force
and velocity series and the parameter events, ``analyze_bag`` splits a session where its
parameters change and measures transparency, vibration and energy per segment, ``report``
formats the results, ``plots`` draws them, ``write`` creates bags from arrays, and ``cli`` is
``haptic-analyze``.
"""

from haptic_dob.bag.analyze import (
    AnalysisSettings,
    BagAnalysis,
    Figures,
    SegmentResult,
    analyze_arrays,
    analyze_bag,
)
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.reader import BagData, Selection, read_bag

__all__ = [
    "AnalysisSettings",
    "BagAnalysis",
    "BagData",
    "BagError",
    "Figures",
    "SegmentResult",
    "Selection",
    "analyze_arrays",
    "analyze_bag",
    "read_bag",
]
