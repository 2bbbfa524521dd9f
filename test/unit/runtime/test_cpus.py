"""CPU affinity: the pinning plan of haptic-launch --pin, the checks, pinning every thread."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from haptic_dob.runtime.cpus import available_cpus, checked_cpus, placement

LOOP = ["device_node", "environment_node", "controller_node", "observer_node"]


def test_two_cpus_pair_the_nodes_along_the_critical_path() -> None:
    """Device and controller (never busy in the same part of a cycle) share one CPU."""
    plan = placement([*LOOP, "recorder_node"], [0, 1])
    assert plan == {
        "device_node": [0],
        "controller_node": [0],
        "environment_node": [1],
        "observer_node": [1],
    }  # the recorder is not a loop node: it stays where the system puts it
    assert placement(LOOP, [2, 5]) == {
        "device_node": [2],
        "controller_node": [2],
        "environment_node": [5],
        "observer_node": [5],
    }
    assert placement(LOOP, [0, 1, 2]) == placement(LOOP, [0, 1])


def test_four_cpus_give_each_loop_node_its_own() -> None:
    plan = placement(LOOP, [0, 1, 2, 3, 4])
    assert sorted(c for cpus in plan.values() for c in cpus) == [0, 1, 2, 3]
    assert set(plan) == set(LOOP)


def test_a_subset_of_the_nodes_is_placed_alone() -> None:
    """``--only``-style graphs: only the nodes present get a CPU."""
    assert placement(["device_node"], [0, 1]) == {"device_node": [0]}
    assert placement(["environment_node", "controller_node"], [0, 1]) == {
        "controller_node": [0],
        "environment_node": [1],
    }


def test_one_cpu_cannot_be_planned() -> None:
    with pytest.raises(ValueError, match="at least 2 CPUs, this process may use 1"):
        placement(LOOP, [0])


@pytest.mark.parametrize(
    ("values", "message"),
    [
        ([0.5], "0.5 is not a CPU number"),
        ([-1], "-1 is not a CPU number"),
        ([True], "True is not a CPU number"),
        ([4096], "CPU 4096 not available to this process (available: "),
    ],
)
def test_unusable_cpus_are_refused_with_the_reason(values: list, message: str) -> None:
    with pytest.raises(ValueError, match=message.replace("(", r"\(")):
        checked_cpus(values)


def test_checked_cpus_are_sorted_integers() -> None:
    cpus = available_cpus()
    assert checked_cpus([float(c) for c in reversed(cpus)] + [cpus[0]]) == cpus


@pytest.mark.skipif(len(available_cpus()) < 2, reason="one CPU: pinning changes nothing")
def test_pin_process_pins_every_thread_also_those_started_before() -> None:
    """The middleware's threads exist before the node reads its parameters: all get pinned, and
    a thread started afterwards inherits the affinity. Run in a child, not in pytest itself."""
    cpu = available_cpus()[-1]
    code = textwrap.dedent(
        f"""
        import os, threading
        from haptic_dob.runtime.cpus import pin_process
        stop = threading.Event()
        early = threading.Thread(target=stop.wait)
        early.start()
        pin_process([{cpu}])
        late = threading.Thread(target=stop.wait)
        late.start()
        tids = [int(t) for t in os.listdir("/proc/self/task")]
        print(len(tids), sorted({{c for t in tids for c in os.sched_getaffinity(t)}}))
        stop.set()
        """
    )
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True
    )
    assert out.stdout.split(maxsplit=1) == ["3", f"[{cpu}]\n"]
