"""Soak benchmark: the slide graph in real time for a long while; memory and deadlines.

Starts ``haptic-launch slide_sim [LAUNCH_ARG ...]`` (by default the loop in one process)
in real-time mode on a fresh domain (localhost discovery) for
``--minutes`` of wall time, samples the resident memory (``VmRSS``) of every node process once a
``--every`` seconds, and at the end reads the device's cycle statistics (``stats_file``). Memory
growth is measured from the first sample after ``--warmup`` seconds to the end, per process.

    .venv/bin/python scripts/soak.py --minutes 30
    .venv/bin/python scripts/soak.py --minutes 30 -- --processes --set controller_node:mode=DOB
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path


def children(pid: int) -> dict[int, str]:
    """{pid: command name} of the direct children of ``pid``."""
    out = {}
    for status in Path("/proc").glob("[0-9]*/status"):
        try:
            fields = dict(
                line.split(":", 1) for line in status.read_text().splitlines() if ":" in line
            )
        except OSError:
            continue
        if int(fields.get("PPid", "0").strip()) == pid:
            cmdline = (status.parent / "cmdline").read_bytes().split(b"\0")
            name = next(
                (
                    Path(a.decode()).name
                    for a in cmdline
                    if b"node" in a or a.endswith(b"container")
                ),
                "?",
            )
            out[int(status.parent.name)] = name
    return out


def rss_kib(pid: int) -> int | None:
    """Resident set size of ``pid`` (KiB), None once it is gone."""
    try:
        for line in Path(f"/proc/{pid}/status").read_text().splitlines():
            if line.startswith("VmRSS:"):
                return int(line.split()[1])
    except OSError:
        return None
    return None


def main(argv: list[str] | None = None) -> int:
    """Run the soak and print one JSON object."""
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument("--minutes", type=float, default=30.0, help="wall time (default 30)")
    p.add_argument("--warmup", type=float, default=60.0, help="s before the memory baseline")
    p.add_argument("--every", type=float, default=10.0, help="s between memory samples")
    p.add_argument(
        "launch_args", nargs="*", metavar="LAUNCH_ARG", help="more haptic-launch arguments"
    )
    a = p.parse_args(argv)
    duration = a.minutes * 60.0
    with tempfile.TemporaryDirectory() as tmp:
        stats = os.path.join(tmp, "stats.json")
        env = dict(
            os.environ,
            ROS_DOMAIN_ID=str(random.randint(1, 100)),
            ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST",
        )
        launcher = os.path.join(os.path.dirname(sys.executable), "haptic-launch")
        argv_launch = [launcher, "slide_sim", *a.launch_args]
        for item in (
            "device_node:clock_mode=realtime",
            "device_node:duration_s=0.0",
            f"device_node:stats_file={stats}",
        ):
            argv_launch += ["--set", item]
        log = open(os.path.join(tmp, "launch.log"), "w")  # noqa: SIM115
        proc = subprocess.Popen(argv_launch, env=env, stdout=log, stderr=subprocess.STDOUT)
        t0 = time.monotonic()
        samples: list[tuple[float, dict[str, int]]] = []
        try:
            while time.monotonic() - t0 < duration:
                time.sleep(a.every)
                if proc.poll() is not None:
                    raise RuntimeError(f"the graph stopped early (exit {proc.returncode})")
                now = {}
                for pid, name in children(proc.pid).items():
                    kib = rss_kib(pid)
                    if kib is not None:
                        now[name] = kib
                samples.append((time.monotonic() - t0, now))
        finally:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            log.close()
        with open(stats, encoding="utf-8") as fh:
            cycle = json.load(fh)
    base = next(s for t, s in samples if t >= a.warmup)
    end = samples[-1][1]
    growth = {n: 100.0 * (end[n] - base[n]) / base[n] for n in base if n in end}
    print(
        json.dumps(
            {
                "minutes": a.minutes,
                "rss_baseline_kib": base,
                "rss_end_kib": end,
                "rss_growth_pct": {n: round(g, 2) for n, g in growth.items()},
                "max_rss_growth_pct": round(max(growth.values()), 2),
                "device": cycle,
            },
            indent=1,
        )
    )
    return 0


if __name__ == "__main__":
    sys.exit(main())
