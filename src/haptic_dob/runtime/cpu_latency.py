"""A CPU wake-up latency request (Linux PM QoS) held while a node process runs its loop.

Between two messages of a cycle a node process sleeps, and so does its CPU when nothing else runs
there. Waking a CPU from a deep idle state takes time, and on a virtual machine much more: a
halted virtual CPU waits for the host to schedule it again (BENCHMARKS.md measures the hand-over
with and without the request). Writing a latency bound in microseconds to ``/dev/cpu_dma_latency``
and keeping the file open asks the kernel to use only idle states whose advertised exit latency
is within that bound (0: the CPU polls instead of sleeping; a virtual machine's halt state
advertises about 1 us, however long the host takes, so there only 0 helps); closing it, or the
process ending, withdraws the request. This is what ``cyclictest`` and real-time control stations
do. It costs power (an idle CPU spins), so it is asked for, never the default, and it needs write
access to the device (root, as a rule).
"""

from __future__ import annotations

import os
import struct

PM_QOS_PATH = "/dev/cpu_dma_latency"
NO_REQUEST = -1  # the parameter value that leaves the CPUs' idle states alone
_S32 = struct.Struct("=i")  # the kernel reads and writes the bound as a native 32-bit integer


def hold(latency_us: int, path: str = PM_QOS_PATH) -> int:
    """Ask that CPUs wake within ``latency_us`` (us) while the returned descriptor stays open.

    ``ValueError`` with the reason when the bound is negative or the request cannot be made.
    """
    if isinstance(latency_us, bool) or int(latency_us) != latency_us or latency_us < 0:
        raise ValueError(f"cpu_latency_us: {latency_us!r} is not a latency (an integer >= 0 us)")
    try:
        fd = os.open(path, os.O_WRONLY)
    except OSError as exc:
        raise ValueError(
            f"cpu_latency_us: cannot open {path} ({exc.strerror}); the request needs Linux and "
            "write access to that device (root, as a rule)"
        ) from None
    try:
        os.write(fd, _S32.pack(int(latency_us)))
    except OSError as exc:
        os.close(fd)
        raise ValueError(f"cpu_latency_us: {path} refused {latency_us} ({exc.strerror})") from None
    return fd


def current(path: str = PM_QOS_PATH) -> int:
    """The bound (us) the kernel applies now: the smallest of all requests held."""
    with open(path, "rb") as fh:
        return int(_S32.unpack(fh.read(_S32.size))[0])


def strictest(values: list[int]) -> int:
    """The bound a process holds for its nodes' requests: the smallest one, or ``NO_REQUEST``."""
    asked = [int(v) for v in values if v != NO_REQUEST]
    return min(asked) if asked else NO_REQUEST
