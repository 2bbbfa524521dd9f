"""haptic_dob: disturbance-observer-based closed-loop control of haptic interfaces.

The numeric core (``models``, ``observer``, ``control``, ``environment``, ``analysis``) is plain
numpy/scipy/pinocchio with SI arguments and an explicit ``dt``; it never imports rclpy. The ROS 2
nodes in ``haptic_dob.nodes`` are thin wrappers around it.
"""

__version__ = "0.1.0"
