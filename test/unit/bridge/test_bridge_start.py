"""The bridge's start: once the graph is up and settled; its end: duration_s after."""

from __future__ import annotations

from haptic_dob.bridge.start import POLL_S, StartGate


def test_the_gate_opens_after_the_graph_stayed_up_for_the_delay() -> None:
    gate = StartGate(start_delay_s=0.5, duration_s=2.0, now=0.0)
    assert gate.end is None
    assert not gate.look(0.0, "controller_node") and gate.poll_at == POLL_S
    assert not gate.look(0.1, "") and gate.poll_at == 0.6  # up: look again after the delay
    assert not gate.look(0.2, "observer_node")  # gone again: start over
    assert not gate.look(0.3, "")
    assert not gate.look(0.7, "")  # 0.4 s up
    assert gate.look(0.81, "")
    assert gate.end == 0.81 + 2.0


def test_no_duration_no_end() -> None:
    gate = StartGate(start_delay_s=0.0, duration_s=0.0, now=0.0)
    gate.look(0.0, "")
    assert gate.look(0.0, "") and gate.end is None
