"""CPU wake-up latency requests (PM QoS): the request itself, the launcher's --cpu-latency."""

from __future__ import annotations

import os
import struct

import pytest

from haptic_dob.errors import InputError
from haptic_dob.launcher import add_cpu_latency
from haptic_dob.runtime.cpu_latency import NO_REQUEST, current, hold, strictest
from support.paths import can_request_cpu_latency


def test_a_request_writes_the_bound_as_a_32_bit_integer_and_stays_open(tmp_path) -> None:
    path = tmp_path / "qos"
    path.write_bytes(b"")
    fd = hold(25, str(path))
    try:
        os.fstat(fd)  # still open: the request lasts as long as the descriptor
        assert path.read_bytes() == struct.pack("=i", 25)
    finally:
        os.close(fd)


@pytest.mark.parametrize("bad", [-1, -20, 1.5, True])
def test_a_bound_that_is_no_latency_is_refused(tmp_path, bad) -> None:
    with pytest.raises(ValueError, match="is not a latency"):
        hold(bad, str(tmp_path / "qos"))


def test_a_request_that_cannot_be_made_says_why(tmp_path) -> None:
    missing = tmp_path / "no_such_device"
    with pytest.raises(ValueError, match=r"cannot open .*no_such_device \(No such file"):
        hold(0, str(missing))
    with pytest.raises(ValueError, match="cannot open"):
        hold(0, str(tmp_path))  # a directory


def test_a_process_holds_the_strictest_request_of_its_nodes() -> None:
    assert strictest([NO_REQUEST, NO_REQUEST]) == NO_REQUEST
    assert strictest([]) == NO_REQUEST
    assert strictest([NO_REQUEST, 50, 0]) == 0
    assert strictest([300, 50]) == 50


@pytest.mark.skipif(not can_request_cpu_latency(), reason="PM QoS requests need root")
def test_the_kernel_applies_a_request_until_it_is_closed() -> None:
    before = current()
    if before == 0:
        pytest.skip("another process holds a 0 us request already")
    fd = hold(0)
    try:
        assert current() == 0
    finally:
        os.close(fd)
    assert current() == before


def test_cpu_latency_of_the_launcher_goes_to_every_loop_node_unless_given() -> None:
    params = {
        "/**": {},
        "device_node": {},
        "controller_node": {"cpu_latency_us": 20},
        "environment_node": {},
        "recorder_node": {},
    }
    add_cpu_latency(params, 0)
    assert params["device_node"]["cpu_latency_us"] == 0
    assert params["environment_node"]["cpu_latency_us"] == 0
    assert params["controller_node"]["cpu_latency_us"] == 20  # the config's, kept
    assert "cpu_latency_us" not in params["recorder_node"]  # not a loop node
    common = {"/**": {"cpu_latency_us": 10}, "device_node": {}}
    add_cpu_latency(common, 0)
    assert "cpu_latency_us" not in common["device_node"]  # /** applies to it


@pytest.mark.parametrize("bad", [-1, 1_000_001])
def test_cpu_latency_out_of_range_is_one_line(bad) -> None:
    with pytest.raises(InputError, match=rf"--cpu-latency {bad}: must be 0 to 1000000 us"):
        add_cpu_latency({"device_node": {}}, bad)
