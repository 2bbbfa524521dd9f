"""ros2 launch haptic_dob session.launch.py [config:=<yaml>] [namespace:=<ns>] [composed:=true]

The simulated session graph for the ROS 2 command line, the same plan as ``haptic-launch``
(which needs no ROS 2 command line), from the same YAML: the loop's nodes (device, environment,
observer, controller) in one process (``ros2 run haptic_dob container``, their messages handed
over in process) unless ``composed:=false``, in ``namespace``. Every process is required: when
the device finishes a lockstep run (``duration_s``) or any node process ends (a crash, a kill),
the launch shuts the whole graph down, as ``haptic-launch`` does. The device and its controller
share a fresh command token (``command_token``), as under ``haptic-launch``.

It starts no recorder (``haptic-launch --record`` does). To record, start one first in its own
terminal (``ros2 run haptic_dob recorder_node --ros-args -p output:=BAG``, or ``ros2 bag record``
as docs/running.md says) and give a config whose ``device_node`` ``wait_for`` names it.
"""

import shutil
import tempfile
from pathlib import Path

from launch import LaunchDescription
from launch.actions import DeclareLaunchArgument, OpaqueFunction, RegisterEventHandler, Shutdown
from launch.event_handlers import OnShutdown
from launch.substitutions import LaunchConfiguration
from launch_ros.actions import Node

from haptic_dob.runtime.configs import resolve_config
from haptic_dob.launcher import (
    NODES,
    START_ORDER,
    add_command_tokens,
    groups_for,
    resolved_params,
    write_params_file,
)
from haptic_dob.nodes.registry import CONTAINER


def _end_graph(reason):
    """What a process's exit does: shut the launch down, once (not again for each process that
    ends during the shutdown)."""
    return lambda _event, context: None if context.is_shutdown else Shutdown(reason=reason)


def _nodes(context, *args, **kwargs):
    config = resolve_config(LaunchConfiguration("config").perform(context))
    namespace = LaunchConfiguration("namespace").perform(context)
    composed = LaunchConfiguration("composed").perform(context).strip().lower()
    if composed not in ("true", "false"):
        raise ValueError(f"composed must be true or false, got {composed!r}")
    params = resolved_params(config, {})
    names = [n for n in START_ORDER if n in params]
    groups = [
        [n for n in START_ORDER if n in g]  # in start order, as haptic-launch plans them
        for g in groups_for(names, False, composed == "false", ())
        if len(g) > 1
    ]
    # a device and its controller started here share a fresh command token
    add_command_tokens(params, names)
    # one params file for every process, removed when the launch ends
    folder = Path(tempfile.mkdtemp(prefix="haptic-launch-"))
    params_file = str(write_params_file(params, folder))
    out = [
        RegisterEventHandler(
            OnShutdown(on_shutdown=lambda _ev, _ctx: shutil.rmtree(folder, ignore_errors=True))
        )
    ]
    for name in names:
        group = next((g for g in groups if name in g), None)
        if group is None:
            package, executable, _ = NODES[name]
            out.append(
                Node(
                    package=package,
                    executable=executable,
                    name=name,
                    namespace=namespace,
                    parameters=[params_file],
                    output="screen",
                    on_exit=_end_graph(f"{name} ended"),
                )
            )
        elif name == group[-1]:  # one process for the group, where its last node would start
            out.append(
                Node(
                    package=CONTAINER[0],
                    executable=CONTAINER[1],
                    arguments=list(group),
                    namespace=namespace,
                    parameters=[params_file],
                    output="screen",
                    on_exit=_end_graph(f"{', '.join(group)} ended"),
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
            DeclareLaunchArgument("composed", default_value="true",
                                  description="the loop's four nodes in one process (true) or "
                                              "each in its own (false)"),
            OpaqueFunction(function=_nodes),
        ]
    )
