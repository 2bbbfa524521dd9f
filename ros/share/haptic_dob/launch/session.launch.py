"""ros2 launch haptic_dob session.launch.py [config:=<yaml>] [namespace:=<ns>]

The simulated session graph for the ROS 2 command line: one node per section of the config
(device, environment, observer, controller, recorder), each with the config's ``/**`` values
and its own section, in ``namespace``. The same plan as ``haptic-launch`` (which needs no
ROS 2 command line), from the same YAML.
"""

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from haptic_dob.configs import resolve_config
from haptic_dob.launcher import NODES, START_ORDER, resolved_params


def _nodes(context, *args, **kwargs):
    config = resolve_config(LaunchConfiguration("config").perform(context))
    namespace = LaunchConfiguration("namespace").perform(context)
    params = resolved_params(config, {})
    common = params.get("/**", {})
    out = []
    for name in START_ORDER:
        if name not in params:
            continue
        package, executable, _ = NODES[name]
        out.append(
            Node(
                package=package,
                executable=executable,
                name=name,
                namespace=namespace,
                parameters=[{**common, **params[name]}],
                output="screen",
            )
        )
    return out


def generate_launch_description():
    return LaunchDescription(
        [
            DeclareLaunchArgument("config", default_value="slide_sim",
                                  description="session YAML: a path or an installed name"),
            DeclareLaunchArgument("namespace", default_value="",
                                  description="namespace of every node"),
            OpaqueFunction(function=_nodes),
        ]
    )
