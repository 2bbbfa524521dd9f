"""Runs through the ROS 2 node graph: one lockstep session per run, recorded, resumable.

A run is a full set of node parameters (the slide session config with overrides) plus a
recorder. ``execute`` writes ``params.yaml`` into the run's directory, starts the graph with
``haptic-launch`` on a domain of its own (localhost discovery), lets the device finish its
``duration_s`` (the recorder holds the loop back while it lags, and the device waits for it to
write the last sample), and marks the run ``complete``. A complete run is never run again: an
interrupted experiment resumes from the bags already written (a run whose parameters changed
runs again).
"""

from __future__ import annotations

import hashlib
import json
import os
import queue
import random
import shutil
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable
from concurrent.futures import ThreadPoolExecutor, as_completed
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from haptic_dob.launcher import add_recorder
from haptic_dob.runtime.params import load_node_params
from haptic_dob.runtime.params_file import dump_params
from haptic_sim.experiments.records import Cell

COMPLETE = "complete"


@dataclass(frozen=True)
class GraphRun:
    """One recorded lockstep session: a name, its node parameters and the cell it measures."""

    name: str
    params: dict[str, dict[str, Any]]  # node name or "/**" -> dotted parameter values
    cell: Cell
    label: str = ""  # for progress lines

    @property
    def duration_s(self) -> float:
        """Simulated length of the session (s)."""
        return float(self.params["device_node"]["duration_s"])


def session_params(
    base_config: Path, overrides: dict[str, dict[str, Any]]
) -> dict[str, dict[str, Any]]:
    """The base config's node sections with ``overrides`` laid over them."""
    params = load_node_params(base_config)
    for node, values in overrides.items():
        params.setdefault(node, {}).update(values)
    return params


def run_dir(root: Path, run: GraphRun) -> Path:
    """Where a run's parameters, bag, log and results live."""
    return root / "runs" / run.name


def bag_path(root: Path, run: GraphRun) -> Path:
    """The run's bag directory."""
    return run_dir(root, run) / "bag"


def is_complete(root: Path, run: GraphRun) -> bool:
    """True when the run finished, its bag is closed, and it ran with these very parameters."""
    d = run_dir(root, run)
    if not bag_path(root, run).is_dir():
        return False
    try:
        marker = json.loads((d / COMPLETE).read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return False
    return isinstance(marker, dict) and marker.get("params_digest") == params_digest(run)


def params_digest(run: GraphRun) -> str:
    """A digest of the run's node parameters (what decides whether a recorded run still holds)."""
    text = json.dumps(run.params, sort_keys=True, default=str)
    return hashlib.sha256(text.encode()).hexdigest()


def _params_yaml(run: GraphRun, bag: Path) -> str:
    params = {k: dict(v) for k, v in run.params.items()}
    add_recorder(params, str(bag), "mcap")
    doc = {"/**" if k == "/**" else f"/**/{k}": {"ros__parameters": v} for k, v in params.items()}
    return dump_params(doc)


class Stopper:
    """Launch processes alive now, so that Ctrl-C or a failed run stops every one of them."""

    def __init__(self) -> None:
        self.stopping = threading.Event()
        self._live: set[subprocess.Popen[bytes]] = set()
        self._lock = threading.Lock()

    def add(self, proc: subprocess.Popen[bytes]) -> None:
        """Track a launch (stopped at once if a stop was asked for already)."""
        with self._lock:
            self._live.add(proc)
        if self.stopping.is_set():
            proc.send_signal(signal.SIGINT)

    def discard(self, proc: subprocess.Popen[bytes]) -> None:
        """Forget a launch that ended."""
        with self._lock:
            self._live.discard(proc)

    def stop(self) -> None:
        """Ask every live launch to stop (SIGINT: the launcher stops its nodes cleanly)."""
        self.stopping.set()
        with self._lock:
            for proc in self._live:
                proc.send_signal(signal.SIGINT)


def execute(
    root: Path, run: GraphRun, domain_id: int, timeout_s: float, stopper: Stopper | None = None
) -> float:
    """Run ``run`` through the node graph unless it is complete; returns the wall time (s).

    Raises ``RuntimeError`` with the end of the launch log when the graph fails (or was stopped).
    """
    d = run_dir(root, run)
    if is_complete(root, run):
        return 0.0
    if d.exists():
        shutil.rmtree(d)  # an interrupted run: its bag may be open or short
    d.mkdir(parents=True)
    bag = bag_path(root, run)
    (d / "params.yaml").write_text(_params_yaml(run, bag), encoding="utf-8")
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain_id))
    env.pop("ROS_STATIC_PEERS", None)
    launcher = str(Path(sys.executable).parent / "haptic-launch")
    t0 = time.monotonic()
    with open(d / "launch.log", "w", encoding="utf-8") as log:
        proc = subprocess.Popen(
            [launcher, str(d / "params.yaml"), "--network", "localhost"],
            env=env,
            stdout=log,
            stderr=subprocess.STDOUT,
            start_new_session=True,
        )
        if stopper is not None:
            stopper.add(proc)
        try:
            code = proc.wait(timeout_s)
        except subprocess.TimeoutExpired:
            proc.send_signal(signal.SIGINT)
            try:
                proc.wait(30)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()
            code = -1
        finally:
            if stopper is not None:
                stopper.discard(proc)
    wall = time.monotonic() - t0
    if stopper is not None and stopper.stopping.is_set():
        raise RuntimeError(f"run {run.name} stopped")  # its bag is short: never marked complete
    if code != 0:
        tail = (d / "launch.log").read_text(encoding="utf-8")[-3000:]
        raise RuntimeError(f"run {run.name} failed (code {code}) after {wall:.0f} s:\n{tail}")
    marker = {"wall_s": wall, "params_digest": params_digest(run)}
    (d / COMPLETE).write_text(json.dumps(marker), encoding="utf-8")
    return wall


def execute_all(
    root: Path,
    runs: Iterable[GraphRun],
    workers: int,
    rtf_guess: float = 1.0,
    progress: Callable[[str], None] | None = None,
) -> dict[str, float]:
    """Execute the runs, ``workers`` at a time on separate domains; {name: wall time}."""
    runs = list(runs)
    todo = [r for r in runs if not is_complete(root, r)]
    say = progress or (lambda _s: None)
    done = len(runs) - len(todo)
    if done:
        say(f"{done} of {len(runs)} runs already recorded (resuming)")
    n_workers = max(workers, 1)
    domains: queue.Queue[int] = queue.Queue()
    for d in random.sample(range(101, 231), n_workers):  # one domain per concurrent run
        domains.put(d)
    walls: dict[str, float] = {}
    counter = {"n": done}
    lock = threading.Lock()

    def one(run: GraphRun, stopper: Stopper) -> None:
        if stopper.stopping.is_set():
            return
        budget = 120.0 + 4.0 * run.duration_s / max(rtf_guess, 0.1)
        domain = domains.get()
        try:
            wall = execute(root, run, domain, budget, stopper)
        finally:
            domains.put(domain)
        with lock:
            walls[run.name] = wall
            counter["n"] += 1
            say(
                f"[{counter['n']:>3}/{len(runs)}] {run.label or run.name}: "
                f"{run.duration_s:g} s simulated in {wall:.1f} s"
            )

    stopper = Stopper()
    ex = ThreadPoolExecutor(n_workers)
    futures = [ex.submit(one, r, stopper) for r in todo]
    try:
        for f in as_completed(futures):
            f.result()
    except BaseException:  # Ctrl-C or a failed run: stop the others, keep what is complete
        stopper.stop()
        for f in futures:
            f.cancel()
        ex.shutdown(wait=True)
        raise
    ex.shutdown()
    return walls
