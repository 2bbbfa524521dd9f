"""Topic names, frames and the stamp conventions of the haptic loop.

Names are relative so a device and its loop can live in a namespace (``/slide1/joint_states``);
``/clock`` and ``/diagnostics`` are global as ROS expects them.
"""

from __future__ import annotations

# device -> everyone
JOINT_STATES = "joint_states"  # sensor_msgs/JointState: q, qd, effort applied over [k-1, k)
EE_POSE = "ee_pose"  # geometry_msgs/PoseStamped: end-effector point (orientation identity)
EE_TWIST = "ee_twist"  # geometry_msgs/TwistStamped: end-effector linear velocity
WRENCH_MEASURED = "wrench_measured"  # geometry_msgs/WrenchStamped: handle force sensor
HAND_WRENCH = "sim/hand_wrench"  # geometry_msgs/WrenchStamped: true hand force (evaluation only)
CLOCK = "/clock"  # rosgraph_msgs/Clock, lockstep only
# environment -> controller
WRENCH_DESIRED = "wrench_desired"  # geometry_msgs/WrenchStamped: wall force on the hand
# observer -> controller
WRENCH_ESTIMATE = "wrench_estimate"  # geometry_msgs/WrenchStamped: estimated hand force
EFFORT_ESTIMATE = "effort_estimate"  # sensor_msgs/JointState: estimated external joint effort
# teleoperation: the channel's slave end -> the slave's controller
POSE_DESIRED = "pose_desired"  # geometry_msgs/PoseStamped: the point the slave tracks
# controller -> device
EFFORT_COMMAND = "effort_command"  # std_msgs/Float64MultiArray, joint order
DIAGNOSTICS = "/diagnostics"  # diagnostic_msgs/DiagnosticArray
# recorder -> device (lockstep back-pressure): the newest stamp written for every recorded topic
# (std_msgs/Header: stamp, and the recorder's name in frame_id)
RECORDER_PROGRESS = "recorder/progress"
# progress stamp of a recorder whose readers have not all matched their writers yet (-1 s): the
# device does not send sample 0 while a recorder says this (the loop's topics are volatile)
PROGRESS_NOT_MATCHED_NS = -1_000_000_000
PARAMETER_EVENTS = "/parameter_events"  # rcl_interfaces/ParameterEvent

#: the topics of one session and their message types (what the recorder records)
SESSION_TOPICS: dict[str, str] = {
    JOINT_STATES: "sensor_msgs/msg/JointState",
    EE_POSE: "geometry_msgs/msg/PoseStamped",
    EE_TWIST: "geometry_msgs/msg/TwistStamped",
    WRENCH_MEASURED: "geometry_msgs/msg/WrenchStamped",
    HAND_WRENCH: "geometry_msgs/msg/WrenchStamped",
    WRENCH_DESIRED: "geometry_msgs/msg/WrenchStamped",
    WRENCH_ESTIMATE: "geometry_msgs/msg/WrenchStamped",
    EFFORT_ESTIMATE: "sensor_msgs/msg/JointState",
    EFFORT_COMMAND: "std_msgs/msg/Float64MultiArray",
}

DEFAULT_BASE_FRAME = "base_link"

#: choices of a loop node's ``input_reliability`` (QoS of its loop inputs, ``ros.qos.loop_input``)
INPUT_RELIABILITY = ("reliable", "best_effort")
