"""Console entry points of the control-side node executables (quiet Ctrl-C at start-up)."""

from __future__ import annotations

from haptic_dob.runtime.entry import run_main


def environment_node() -> int:
    """``haptic-environment-node``."""
    return run_main("haptic_dob.nodes.environment_node")


def observer_node() -> int:
    """``haptic-observer-node``."""
    return run_main("haptic_dob.nodes.observer_node")


def controller_node() -> int:
    """``haptic-controller-node``."""
    return run_main("haptic_dob.nodes.controller_node")


def channel_node() -> int:
    """``haptic-channel-node``."""
    return run_main("haptic_dob.nodes.channel_node")


def slave_controller_node() -> int:
    """``haptic-slave-controller-node``."""
    return run_main("haptic_dob.nodes.slave_controller_node")


def bridge_node() -> int:
    """``haptic-bridge-node``."""
    return run_main("haptic_dob.nodes.bridge_node")


def recorder_node() -> int:
    """``haptic-recorder-node``."""
    return run_main("haptic_dob.nodes.recorder_node")


def container() -> int:
    """``haptic-container``."""
    return run_main("haptic_dob.nodes.container")
