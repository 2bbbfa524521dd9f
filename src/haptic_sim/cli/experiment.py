"""``haptic-experiment``: the thesis's experiments through the node graph, and a report.

Parts (``--parts``, all by default; docs/reproduction.md): ``ch4`` identification and model
verification, ``ch5`` the observer against the force sensor, ``ch7`` transparency, ``ch6``
vibration onset, ``slave`` the teleoperation slave's model (node graph, recorded); ``map`` the
stability map, ``dob`` the DOB wall at Kf = 100, ``sweeps`` Table 7.1's cells against the
parameter responsible, ``phantom`` thesis 5.2 (batch).

Graph runs go ``--workers`` at a time, each on a ROS domain of its own (default: as many as the
free CPUs carry, a graph run or a batch job counting one); a run whose bag is complete is not
run again, so an interrupted experiment resumes (``--fresh`` starts over). The bags are analysed
as ``haptic-analyze`` does (``runs/*/analysis.json``), and ``report.md`` with its figures and
``results.json`` are written to ``--out``. ``--quick`` runs only OL, CL Kf=2 and DOB Kf=1 at
800 N/m for 40 s (the demo).
"""

from __future__ import annotations

import json
import shutil
import signal
import sys
import time
from collections.abc import Callable
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from functools import partial
from pathlib import Path
from typing import Any, TypeVar

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.errors import InputError
from haptic_dob.runtime.configs import resolve_config
from haptic_dob.runtime.cpus import free_cpus, workers_for
from haptic_sim.experiments import graph_runs, report, results
from haptic_sim.experiments.entry import BatchJob, Experiment, GraphJob
from haptic_sim.experiments.jsonio import from_json, to_json
from haptic_sim.experiments.parts import EXPERIMENTS, PARTS, QUICK_PARTS, save_results
from haptic_sim.experiments.plan import QUICK_DURATION_S
from haptic_sim.experiments.records import ExperimentResults
from haptic_sim.slide.session import SessionConfig

#: CPUs one recorded graph run is given: the composed loop and the recorder take turns in
#: lockstep (about 1.5 CPUs busy on average); two runs on 2 free CPUs turn 1.37x the runs over
GRAPH_RUN_CPUS = 1

R = TypeVar("R")


@dataclass(frozen=True)
class Setting:
    """What one ``haptic-experiment`` works with: where, from which config, how many at a time."""

    root: Path  # --out
    config_path: Path
    base: SessionConfig
    seed: int
    quick: bool
    graph_workers: int  # graph runs at a time
    batch_workers: int  # batch jobs (and bag analyses) at a time

    @property
    def figures(self) -> Path:
        """The report's figure directory."""
        return self.root / "figures"


def _say(text: str) -> None:
    print(text, flush=True)


def _parts(text: str) -> list[str]:
    parts = [p.strip() for p in text.split(",") if p.strip()]
    bad = [p for p in parts if p not in PARTS]
    if bad or not parts:
        raise InputError(
            f"--parts takes a comma-separated subset of {','.join(PARTS)}, got {text!r}"
        )
    return parts


def _cached(path: Path, result_type: type[R], compute: Callable[[], R]) -> R:
    """Batch results are kept in ``path`` (JSON) so that a resumed experiment skips them."""
    if path.is_file():
        try:
            return from_json(result_type, json.loads(path.read_text(encoding="utf-8")))
        except ValueError as exc:
            raise InputError(f"{path}: {exc} (delete it, or start over with --fresh)") from None
    value = compute()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(to_json(value), indent=1) + "\n", encoding="utf-8")
    return value


def run_batch(
    chosen: list[Experiment[Any]], s: Setting, timing: dict[str, float]
) -> dict[str, Any]:
    """The chosen batch parts' results (cached in ``batch/``), their run-time figures drawn."""
    batch = [(e, e.job) for e in chosen if isinstance(e.job, BatchJob)]
    out: dict[str, Any] = {}
    if not batch:
        return out
    with ProcessPoolExecutor(s.batch_workers) as pool:
        for e, job in batch:
            t0 = time.monotonic()
            compute = partial(job.compute, s.base, pool, s.figures)
            out[e.part] = _cached(s.root / "batch" / f"{e.part}.json", e.result_type, compute)
            timing[e.part] = time.monotonic() - t0
            _say(f"{job.done(out[e.part])} ({timing[e.part]:.0f} s)")
    for e, _ in batch:
        for f in e.figures:
            if f.simulate is not None and not (s.figures / f.file).is_file():
                f.simulate(s.base, s.figures / f.file)
    return out


def run_graph(
    chosen: list[Experiment[Any]], s: Setting, timing: dict[str, float]
) -> dict[str, Any]:
    """The chosen graph parts' results: every run recorded (or resumed), analysed, collected."""
    planned = [
        (e, e.job, e.job.runs(s.config_path, s.seed, s.quick))
        for e in chosen
        if isinstance(e.job, GraphJob)
    ]
    runs = [r for _, _, rs in planned for r in rs]
    if not runs:
        return {}
    t0 = time.monotonic()
    sim = sum(r.duration_s for r in runs)
    _say(f"{len(runs)} node-graph runs ({sim:g} s simulated), {s.graph_workers} at a time")
    try:
        graph_runs.execute_all(s.root, runs, s.graph_workers, rtf_guess=1.0, progress=_say)
    except RuntimeError as exc:
        raise InputError(str(exc).splitlines()[0] + " (see its launch.log)") from None
    timing["graph_runs"] = time.monotonic() - t0
    t0 = time.monotonic()
    analysed = [r for _, job, rs in planned if job.analyse for r in rs]
    with ProcessPoolExecutor(s.batch_workers) as pool:
        figures = pool.map(results.analyse_run, [s.root] * len(analysed), analysed)
        done = {r.name: a for r, a in zip(analysed, figures, strict=True)}
    rows = [done.get(r.name) or results.unanalysed(s.root, r) for r in runs]
    timing["analysis"] = time.monotonic() - t0
    _say(f"analysed {len(rows)} bags ({timing['analysis']:.0f} s)")
    out: dict[str, Any] = {}
    first = 0
    for e, job, part_runs in planned:
        out[e.part] = job.collect(rows[first : first + len(part_runs)], s.base)
        first += len(part_runs)
    return out


def command(
    out: str,
    config: str,
    parts_text: str,
    quick: bool,
    workers: int | None,
    seed: int,
    fresh: bool,
) -> int:
    """Run the chosen parts, analyse, write the report; raises on bad input or a failed run."""
    if workers is not None and workers < 1:
        raise InputError(f"--workers must be >= 1, got {workers}")
    if seed < 0:
        raise InputError(f"--seed must be >= 0, got {seed}")
    parts = QUICK_PARTS if quick else _parts(parts_text)
    chosen = [e for e in EXPERIMENTS if e.part in parts]
    config_path = resolve_config(config)
    root = Path(out)
    if fresh and root.exists():
        if not (root / "results.json").is_file() and not (root / "runs").is_dir():
            raise InputError(f"--fresh: {root} does not look like an experiment directory")
        shutil.rmtree(root)
    (root / "figures").mkdir(parents=True, exist_ok=True)
    base = SessionConfig.from_yaml(config_path)
    t_start = time.monotonic()
    if workers is None:
        free = free_cpus()
        graph_workers, batch_workers = workers_for(GRAPH_RUN_CPUS, free), workers_for(1, free)
        basis = f"{free:.1f} CPUs free"
    else:
        graph_workers = batch_workers = workers
        basis = "--workers"
    _say(
        f"haptic-experiment: {', '.join(parts)} -> {root}/ ({graph_workers} graph run(s) and "
        f"{batch_workers} batch job(s) at a time: {basis})"
    )
    s = Setting(root, config_path, base, seed, quick, graph_workers, batch_workers)
    timing: dict[str, float] = {}
    # the batch parts first: they use every core for a short while
    outputs = run_batch(chosen, s, timing)
    outputs.update(run_graph(chosen, s, timing))
    timing["total"] = time.monotonic() - t_start
    res = ExperimentResults(
        config=str(config),
        config_params=graph_runs.session_params(config_path, {}),
        quick=quick,
        seed=seed,
        parts=parts,
        results=outputs,
        timing_s=timing,
    )
    save_results(root / "results.json", res)
    path = report.write(root, res, base)
    _say(report.console_summary(res))
    _say(f"report: {path} (total {timing['total']:.0f} s)")
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-experiment``."""
    p = ArgumentParser(
        prog="haptic-experiment",
        description=__doc__.split("\n\n")[0],
        epilog="Parts: " + ", ".join(PARTS) + ". See the module help in the README.",
    )
    p.add_argument("--out", default="report", metavar="DIR", help="report directory (report)")
    p.add_argument("--config", default="slide_sim", help="base session config (default: slide_sim)")
    p.add_argument(
        "--parts", default=",".join(PARTS), metavar="LIST", help="comma-separated parts (all)"
    )
    p.add_argument(
        "--quick",
        action="store_true",
        help=f"OL, CL Kf=2, DOB Kf=1 at 800 N/m for {QUICK_DURATION_S:g} s (the demo)",
    )
    p.add_argument(
        "--workers",
        type=int,
        default=None,
        help="graph runs and batch jobs at a time (default: what the free CPUs carry, measured "
        f"at the start: {GRAPH_RUN_CPUS} per graph run, 1 per batch job)",
    )
    p.add_argument("--seed", type=int, default=0, help="seed of the hand motion (default 0)")
    p.add_argument("--fresh", action="store_true", help="delete --out first instead of resuming")
    a = p.parse_args(argv)
    signal.signal(signal.SIGTERM, _interrupt)  # stop like Ctrl-C: every launch, then exit 130
    return run(lambda: command(a.out, a.config, a.parts, a.quick, a.workers, a.seed, a.fresh))


def _interrupt(_signum: int, _frame: object) -> None:
    raise KeyboardInterrupt


if __name__ == "__main__":
    sys.exit(main())
