"""The cost of a log call on the loop's path: rclpy's logger against ``LoopLog``.

Each run is a fresh process (this file, ``python scripts/bench_log.py LOGGER``) holding the
modules a device process holds: its first call is the costly one (``inspect`` maps every loaded
module to its file). Its stderr is thrown away. Per logger: the first call, then the median of
calls said and of calls a 5 s throttle keeps quiet, each from a call site in this file.
"""

from __future__ import annotations

import json
import statistics
import subprocess
import sys
import time
from pathlib import Path
from typing import Any

CALLS = 200


def _measure(name: str) -> dict[str, Any]:
    """In the child: one logger's first call and its calls said and throttled away (s)."""
    # lazy: the child loads what a device process has; benchmarks.py stays without rclpy
    import rclpy.logging

    import haptic_sim.nodes.device_node  # noqa: F401  # what a device process has loaded
    from haptic_dob.runtime.ros.log import LoopLog

    ros = rclpy.logging.get_logger("bench_log")
    log: Any = ros if name == "rclpy" else LoopLog(ros)

    def said(i: int) -> None:
        log.warning(f"trip {i}")

    def quiet(i: int) -> None:
        log.warning(f"trip {i}", throttle_duration_sec=5.0)

    t = time.perf_counter()
    said(-1)
    first = time.perf_counter() - t
    quiet(-1)  # the throttle's first line
    out: dict[str, Any] = {"first": first}
    for label, call in (("said", said), ("throttled", quiet)):
        ts = []
        for i in range(CALLS):
            t = time.perf_counter()
            call(i)
            ts.append(time.perf_counter() - t)
        out[label] = statistics.median(ts)
    return out


def _run(name: str) -> dict[str, float]:
    proc = subprocess.run(
        [sys.executable, str(Path(__file__).resolve()), name],
        stdout=subprocess.PIPE,
        stderr=subprocess.DEVNULL,
        stdin=subprocess.DEVNULL,
        text=True,
        timeout=300,
    )
    if proc.returncode != 0:
        raise RuntimeError(f"bench_log {name} exited {proc.returncode}")
    result: dict[str, float] = json.loads(proc.stdout.strip().splitlines()[-1])
    return result


def bench_log(repeat: int) -> str:
    """Per logger (each in fresh processes): first call, median said, median throttled away."""
    rows: dict[str, dict[str, list[float]]] = {}
    for _ in range(repeat):
        for name in ("rclpy", "LoopLog"):
            r = _run(name)
            row = rows.setdefault(name, {"first": [], "said": [], "throttled": []})
            for key in row:
                row[key].append(r[key])
    return "; ".join(
        f"{name}: first call {statistics.median(r['first']) * 1e3:.1f} ms, said "
        f"{statistics.median(r['said']) * 1e6:.0f} us, throttled away "
        f"{statistics.median(r['throttled']) * 1e6:.1f} us"
        for name, r in rows.items()
    )


if __name__ == "__main__":
    print(json.dumps(_measure(sys.argv[1])))
