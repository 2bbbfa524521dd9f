"""CPU affinity of a node process, and where the loop's nodes go when a launch pins them.

A lockstep cycle is a chain device -> environment -> controller -> device, with the observer
beside it. On a 2-core machine the scheduler moves the four processes between the cores at every
hand-over, and each move costs the process its warm caches. Pinning the device and the controller
(which never run at the same time in a cycle) to one CPU and the environment and the observer to
the other keeps every process on warm caches (BENCHMARKS.md, "pinned", measures what it gains).
As in ros2_control's controller
manager (its ``cpu_affinity`` parameter), pinning is asked for, never the default: a pinned process
cannot move away from a core that other work occupies. ``scheduling`` says how the process is
scheduled.
"""

from __future__ import annotations

import contextlib
import os
import time
from collections.abc import Iterable, Mapping, Sequence

#: the loop's nodes sharing one CPU when only two are available (the critical-path pairs)
PAIRS = (("device_node", "controller_node"), ("environment_node", "observer_node"))


def available_cpus() -> list[int]:
    """The CPUs this process may run on (all of them, where the system cannot say)."""
    if hasattr(os, "sched_getaffinity"):
        return sorted(os.sched_getaffinity(0))
    return list(range(os.cpu_count() or 1))


def checked_cpus(values: Iterable[float | int]) -> list[int]:
    """``values`` as sorted CPU numbers; ``ValueError`` with the reason if one is not usable."""
    cpus: set[int] = set()
    for v in values:
        if isinstance(v, bool) or float(v) != int(v) or int(v) < 0:
            raise ValueError(f"cpu_affinity: {v!r} is not a CPU number (an integer >= 0)")
        cpus.add(int(v))
    usable = available_cpus()
    missing = sorted(cpus.difference(usable))
    if missing:
        raise ValueError(
            f"cpu_affinity: CPU {', '.join(map(str, missing))} not available to this process "
            f"(available: {', '.join(map(str, usable))})"
        )
    return sorted(cpus)


def pin_process(cpus: Sequence[int]) -> None:
    """Run every thread of this process (and the threads it starts later) on ``cpus``.

    The middleware's threads already exist when the parameters are known, so each one is pinned
    (Linux: ``/proc/self/task``); threads started later inherit the affinity of their creator.
    """
    if not hasattr(os, "sched_setaffinity"):
        raise ValueError("cpu_affinity: this system cannot pin processes to CPUs (Linux only)")
    wanted = set(cpus)
    done: set[int] = set()
    while True:  # again while threads appear (one not yet pinned may start another)
        try:
            threads = {int(t) for t in os.listdir("/proc/self/task")} - done
        except OSError:
            threads = {0} - done
        if not threads:
            return
        for tid in threads:
            with contextlib.suppress(ProcessLookupError):  # the thread ended meanwhile
                os.sched_setaffinity(tid, wanted)
        done |= threads


def placement(nodes: Iterable[str], cpus: Sequence[int]) -> dict[str, list[int]]:
    """The CPU of each loop node of ``nodes`` when a launch pins them (other nodes stay free).

    Four or more CPUs: one each. Two or three: the pairs of ``PAIRS`` share a CPU. One: nothing
    to place (``ValueError``).
    """
    present = set(nodes)
    loop = [n for pair in PAIRS for n in pair if n in present]
    if len(cpus) < 2:
        raise ValueError(f"pinning needs at least 2 CPUs, this process may use {len(cpus)}")
    if len(cpus) >= 4:
        return {n: [cpus[i]] for i, n in enumerate(loop)}
    return {n: [cpus[i]] for i, pair in enumerate(PAIRS) for n in pair if n in loop}


def describe(assigned: Mapping[str, Sequence[int]]) -> str:
    """``device_node: 0, controller_node: 0, ...`` for a log line."""
    return ", ".join(f"{n}: {','.join(map(str, c))}" for n, c in assigned.items())


def _cpu_times() -> tuple[float, float] | None:
    """(idle, total) jiffies summed over every CPU (Linux ``/proc/stat``), None elsewhere."""
    try:
        with open("/proc/stat", encoding="ascii") as fh:
            fields = fh.readline().split()[1:]
    except OSError:
        return None
    values = [float(v) for v in fields]
    idle = values[3] + (values[4] if len(values) > 4 else 0.0)  # idle + iowait
    return idle, sum(values[:8])


def free_cpus(sample_s: float = 0.5) -> float:
    """How many of this process's CPUs are idle now: the machine's idle share over ``sample_s``
    seconds times the CPUs this process may use (their count where the system cannot say)."""
    usable = len(available_cpus())
    before = _cpu_times()
    if before is None:
        return float(usable)
    time.sleep(sample_s)
    after = _cpu_times()
    if after is None or after[1] <= before[1]:
        return float(usable)
    idle_share = (after[0] - before[0]) / (after[1] - before[1])
    return max(0.0, min(1.0, idle_share)) * usable


def workers_for(processes_per_job: int, free: float | None = None) -> int:
    """Jobs to run at once so that each of their busy processes has a free CPU (at least one)."""
    free = free_cpus() if free is None else free
    return max(1, int((free + 0.25) // processes_per_job))


def scheduling() -> str:
    """This process's CPU scheduling: ``SCHED_FIFO priority 50`` or ``normal``."""
    if hasattr(os, "sched_getscheduler") and os.sched_getscheduler(0) == os.SCHED_FIFO:
        return f"SCHED_FIFO priority {os.sched_getparam(0).sched_priority}"
    return "normal"
