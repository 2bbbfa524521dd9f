"""When a process of loop nodes stops (``spin.run_over``): at a node's error or a node that
finishes without a run of its own (a recorder's duration) at once; otherwise once every node
that ends its run by itself (a device with a duration) has, so two composed devices (a
teleoperation graph's master and slave) both reach the end of their runs."""

from __future__ import annotations

from types import SimpleNamespace

from haptic_dob.runtime.ros.spin import run_over


def node(finished: bool = False, finishes_run: bool = False, exit_code: int = 0):
    return SimpleNamespace(finished=finished, finishes_run=finishes_run, exit_code=exit_code)


def test_a_lone_device_stops_the_process_at_its_end() -> None:
    assert not run_over([node(finishes_run=True), node()])
    assert run_over([node(finished=True, finishes_run=True), node()])


def test_two_devices_both_finish_their_runs() -> None:
    master, slave = node(finished=True, finishes_run=True), node(finishes_run=True)
    assert not run_over([master, slave, node()])
    slave.finished = True
    assert run_over([master, slave, node()])


def test_an_error_or_a_node_without_a_run_stops_at_once() -> None:
    device = node(finishes_run=True)
    assert run_over([device, node(finished=True)])  # a recorder's duration_s
    assert run_over([device, node(finished=True, finishes_run=True, exit_code=3)])
