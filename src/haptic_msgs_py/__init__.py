"""Topic names, QoS, stamps, the loop's values, their wire format and message conversions,
shared by the haptic_dob nodes and tools (the process runtime lives in ``haptic_dob.runtime``).

Modules here import neither rclpy nor rosbags at module level, so the numeric core and the
bag analysis can use them without a ROS middleware; ``haptic_msgs_py.ros`` holds the parts
that need rclpy.
"""

__version__ = "0.1.0"
