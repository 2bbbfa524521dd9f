"""Run one ``recorder_node`` in this process (``haptic-record``), its parameters given here."""

from __future__ import annotations

from collections.abc import Sequence

from rclpy.context import Context
from rclpy.parameter import Parameter

from haptic_dob.nodes.recorder_node import RecorderNode
from haptic_dob.runtime.ros.spin import run_nodes
from haptic_msgs_py.ament import ensure_ament_prefix


def record(
    output: str,
    storage: str = "mcap",
    namespace: str = "",
    duration_s: float = 0.0,
    topics: Sequence[str] | None = None,
    node_name: str = "recorder_node",
    rate_hz: float = 1000.0,
    log_time: str = "session",
) -> tuple[int, RecorderNode | None]:
    """Run a recorder until SIGINT/SIGTERM or ``duration_s``; (exit code, the node if created)."""
    ensure_ament_prefix()
    overrides = [
        Parameter("output", value=output),
        Parameter("storage", value=storage),
        Parameter("duration_s", value=float(duration_s)),
        Parameter("rate_hz", value=float(rate_hz)),
        Parameter("log_time", value=log_time),
    ]
    if topics is not None:
        overrides.append(Parameter("topics", value=list(topics)))
    made: list[RecorderNode] = []

    def make(ctx: Context) -> list[RecorderNode]:
        made.append(
            RecorderNode(
                context=ctx,
                name=node_name,
                namespace=namespace or None,
                parameter_overrides=overrides,
            )
        )
        return made

    code = run_nodes(make, ["haptic-record"])
    return code, (made[0] if made else None)
