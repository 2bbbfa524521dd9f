"""Recorded sessions: read rosbag2 bags (MCAP, sqlite3) and analyse them segment by segment.

ROS-free (``rosbags`` reads and writes the bags): ``bagfile`` opens a bag and finds its topics,
``read_bag`` (``reader``) streams the motion, hand force and velocity ``series`` and the
``param_events``, ``resample`` puts them on one uniform grid, ``segments`` splits a session where
its parameters change, ``analyze_bag`` (``analyze``) measures transparency, vibration and energy
per segment (``haptic_dob.analysis.analyze_arrays``) into ``results``, ``report`` formats them,
``plots`` draws them, ``write`` creates bags from arrays, and ``cli`` is ``haptic-analyze``.
"""

from haptic_dob.analysis.figures import Figures, analyze_arrays
from haptic_dob.bag.analyze import AnalysisSettings, analyze_bag
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.reader import BagData, Selection, read_bag
from haptic_dob.bag.results import BagAnalysis, SegmentResult

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
