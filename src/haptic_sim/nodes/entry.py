"""Console entry point of the simulated device's executable (quiet Ctrl-C at start-up)."""

from __future__ import annotations

from haptic_dob.runtime.entry import run_main


def device_node() -> int:
    """``haptic-device-node``."""
    return run_main("haptic_sim.nodes.device_node")
