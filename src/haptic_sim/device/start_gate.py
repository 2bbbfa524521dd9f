"""When the simulated device sends sample 0: once the graph is up, and settled.

The graph is up when every ``wait_for`` node is, the known subscribers matched, a command
publisher is seen (``LoopPort.waiting_for``) and every recorder's readers matched
(``RecorderGate.unmatched``). In lockstep, or in real time with ``wait_for``, the gate then
waits ``start_delay_s`` and looks again (entities that came late); real time without
``wait_for`` starts at once. While the graph is not up the device says what it waits for
(every 5 s), so a device that does not start says why. Times are monotonic seconds.
"""

from __future__ import annotations

from haptic_sim.device.port import Log, LoopPort
from haptic_sim.device.recorder_gate import RecorderGate
from haptic_sim.device.settings import DeviceLoopSettings

GRAPH_POLL_S = 0.05  # how often the start and the end of a run look at the graph again


class StartGate:
    """The start of the device's run: ``wait`` says when to look again, or that it may start."""

    def __init__(self, port: LoopPort, recorders: RecorderGate, log: Log) -> None:
        self.port = port
        self.recorders = recorders
        self.log = log
        self.ready_since: float | None = None  # when the graph was first seen up

    def wait(self, now: float, settings: DeviceLoopSettings, settle: bool) -> float | None:
        """None when sample 0 may go out at ``now``; else when to look again. ``settle``: wait
        ``start_delay_s`` once the graph is first up."""
        settling = self.ready_since is not None
        if not self.graph_ready(settings):  # again after the settle time: entities came late
            self.ready_since = None
            return now + GRAPH_POLL_S
        if not settling:
            self.ready_since = now
            if settle:
                return now + settings.start_delay_s
        return None

    def graph_ready(self, settings: DeviceLoopSettings) -> bool:
        """The graph is up (see the module's notes); says what it waits for while not."""
        waiting = self.port.waiting_for()
        if not waiting and self.recorders.unmatched(self.port.recorders()):
            waiting = "the recorders' readers to match the loop's topics"
        if waiting:
            self.log.info(
                f"waiting before sample 0 for {waiting} (wait_for: {list(settings.wait_for)})",
                throttle_duration_sec=5.0,
            )
        return not waiting
