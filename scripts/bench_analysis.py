#!/usr/bin/env python3
"""Benchmark ``haptic-analyze`` end to end: process start to output, and its peak memory.

    .venv/bin/python scripts/bench_analysis.py                 # both bags, MCAP
    .venv/bin/python scripts/bench_analysis.py --only 40s --storage sqlite3 --runs 7

The bags are written with the rosbags writer (``haptic_dob.bag.write``) into ``--dir`` (kept for
the next run) like a recording of the node graph: every session topic at 1 kHz plus
``/parameter_events`` (nine messages per sample). ``40s``: the default 40 s slide session (DOB,
Kf = 1, 800 N/m) from the batch runner; ``1h``: its motion and force repeated 90 times.

Each run times ``haptic-analyze BAG`` as a child process from just before it starts to its exit,
and reads its peak resident memory (``os.wait4`` ``ru_maxrss``); medians of ``--runs`` runs are
printed. The bag files are in the page cache (just written or read by the previous run).
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from haptic_dob.bag.write import write_session_bag
from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_sim.slide.session import SessionConfig, run_session

ROOT = Path(__file__).resolve().parents[1]
ANALYZE = Path(sys.executable).parent / "haptic-analyze"
BAGS = {"40s": 1, "1h": 90}  # name -> how many 40 s sessions back to back
DEFAULT_DIR = Path(tempfile.gettempdir()) / "haptic_dob_bench_bags"  # where the bags are kept


def make_bag(directory: Path, name: str, storage: str) -> Path:
    """Write the named bag (unless it is there already); return its path."""
    path = directory / f"{name}_{storage}"
    if (path / "metadata.yaml").exists():
        return path
    cfg = SessionConfig.from_yaml(ROOT / "config" / "slide_sim.yaml").replace(
        law=ImpedanceLaw(ControlMode.DOB, 1.0, 4.0)
    )
    res = run_session(cfg)
    reps = BAGS[name]
    params = {
        "controller_node": {"mode": "DOB", "kf": 1.0, "max_force_n": 4.0},
        "environment_node": {
            "stiffness_n_per_m": 800.0,
            "damping_n_s_per_m": 0.0,
            "position": [0.0, 0.0, 0.0],
            "normal": [1.0, 0.0, 0.0],
        },
        "observer_node": {"gain": 41.6, "output_limit": 4.0},
    }
    t0 = time.perf_counter()
    n = write_session_bag(
        path,
        np.tile(res.q, reps),
        np.tile(res.force_measured, reps),
        cfg.loop.rate_hz,
        params,
        velocity=np.tile(res.qd, reps),
        storage=storage,
        all_topics=True,
    )
    size = sum(f.stat().st_size for f in path.iterdir())
    print(
        f"wrote {path}: {n} messages, {size / 1e6:.0f} MB in {time.perf_counter() - t0:.0f} s",
        file=sys.stderr,
    )
    return path


def run_once(bag: Path) -> tuple[float, float]:
    """(wall seconds from process start to exit, peak RSS in MB) of one ``haptic-analyze``."""
    t0 = time.perf_counter()
    proc = subprocess.Popen([str(ANALYZE), str(bag)], stdout=subprocess.DEVNULL)
    _, status, usage = os.wait4(proc.pid, 0)
    wall = time.perf_counter() - t0
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        raise SystemExit(f"haptic-analyze {bag} exited with {proc.returncode}")
    return wall, usage.ru_maxrss / 1024.0


def bench_bag(name: str, storage: str, runs: int | None = None) -> str:
    """One line for ``benchmarks.py --tables``: the named bag (in the default ``--dir``) through
    ``haptic-analyze``, median wall time and peak resident memory."""
    DEFAULT_DIR.mkdir(parents=True, exist_ok=True)
    bag = make_bag(DEFAULT_DIR, name, storage)
    n = runs or (5 if name == "40s" else 3)
    samples = [run_once(bag) for _ in range(n)]
    walls, rss = [w for w, _ in samples], [r for _, r in samples]
    size = sum(f.stat().st_size for f in bag.iterdir()) / 1e6
    return (
        f"median {statistics.median(walls):.2f} s of {n} (runs: "
        f"{', '.join(f'{w:.2f}' for w in walls)}), peak RSS {statistics.median(rss):.0f} MB; "
        f"the bag {size:.0f} MB"
    )


def main() -> int:
    p = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    p.add_argument(
        "--dir",
        default=str(DEFAULT_DIR),
        help="where the bags are kept (default: haptic_dob_bench_bags in the temp directory)",
    )
    p.add_argument("--only", choices=sorted(BAGS), help="one bag only")
    p.add_argument("--storage", choices=["mcap", "sqlite3"], default="mcap")
    p.add_argument("--runs", type=int, help="runs per bag (default 5 for 40s, 3 for 1h)")
    p.add_argument("--json", action="store_true", help="print the results as JSON")
    a = p.parse_args()
    directory = Path(a.dir)
    directory.mkdir(parents=True, exist_ok=True)
    results = []
    for name in [a.only] if a.only else list(BAGS):
        bag = make_bag(directory, name, a.storage)
        runs = a.runs or (5 if name == "40s" else 3)
        samples = [run_once(bag) for _ in range(runs)]
        walls, rss = [s[0] for s in samples], [s[1] for s in samples]
        results.append(
            {
                "bag": name,
                "storage": a.storage,
                "runs": runs,
                "wall_s_median": statistics.median(walls),
                "wall_s": [round(w, 3) for w in walls],
                "peak_rss_mb_median": statistics.median(rss),
                "peak_rss_mb": [round(r, 1) for r in rss],
                "command": f"{ANALYZE.name} {bag}",
            }
        )
    if a.json:
        print(json.dumps(results, indent=2))
    else:
        print(
            f"{platform.processor() or platform.machine()}, {os.cpu_count()} CPUs, "
            f"Python {platform.python_version()}"
        )
        for r in results:
            print(
                f"{r['bag']:>4} {r['storage']:<7} end to end {r['wall_s_median']:.2f} s median of "
                f"{r['runs']} {r['wall_s']}, peak RSS {r['peak_rss_mb_median']:.0f} MB"
            )
    return 0


if __name__ == "__main__":
    sys.exit(main())
