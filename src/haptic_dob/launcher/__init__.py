"""``haptic-launch``: one session's node graph from one ``ros__parameters`` YAML.

The tool in four parts: ``options`` (what was asked for, checked), ``node_params`` (the nodes'
parameter table of a launch), ``process_plan`` (which processes run which nodes, with what
command line) and ``supervise`` (start, watch, forward signals, stop); ``haptic_dob.cli.launch``
ties them to the command line (``main``). The names below are the ones other code (the launch file,
the graph
runs, the tests) imports from here.
"""

from haptic_dob.launcher.node_params import (
    add_command_tokens,
    add_cpu_latency,
    add_pinning,
    add_recorder,
    resolved_params,
    write_params_file,
)
from haptic_dob.launcher.options import LaunchOptions, normalize_namespace, parse_sets
from haptic_dob.launcher.process_plan import ProcessSpec, groups_for, plan
from haptic_dob.launcher.supervise import set_rt_priority
from haptic_dob.nodes.registry import NODES, START_ORDER

__all__ = [
    "NODES",
    "START_ORDER",
    "LaunchOptions",
    "ProcessSpec",
    "add_command_tokens",
    "add_cpu_latency",
    "add_pinning",
    "add_recorder",
    "groups_for",
    "normalize_namespace",
    "parse_sets",
    "plan",
    "resolved_params",
    "set_rt_priority",
    "write_params_file",
]
