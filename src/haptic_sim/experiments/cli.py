"""``haptic-experiment``: the thesis's chapters 6 and 7 through the node graph, and a report.

Parts (``--parts``, all by default):

- ``ch7``: transparency, OL / CL Kf=2 / DOB Kf=1 / DOB Kf=25 on walls of 80-2400 N/m, 40 s of
  semi-random hand motion each, run through the node graph in lockstep and recorded;
- ``ch6``: vibration onset through the node graph (push-and-hold protocol, pulse response);
- ``map``: the stability map (onset against Kf, Z-width against wall damping), batch sweeps;
- ``dob``: why the thesis's DOB wall stayed quiet at Kf = 100 (batch, the simulator's knobs);
- ``phantom``: thesis section 5.2 on the PHANToM 1.5 (batch).

Graph runs go ``--workers`` at a time, each on a ROS domain of its own (by default as many as the
free CPUs carry: a run keeps two processes busy, its composed loop and its recorder; batch jobs
one each); a run whose bag is complete is not run again, so an interrupted experiment resumes
(``--fresh`` starts over). The
bags are analysed as ``haptic-analyze`` does (``runs/*/analysis.json``), and ``report.md`` with
its figures and ``results.json`` is written to ``--out``. ``--quick`` runs only OL, CL Kf=2 and
DOB Kf=1 at 800 N/m for 20 s (the demo).
"""

from __future__ import annotations

import json
import shutil
import signal
import sys
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path
from typing import Any

from haptic_dob.cli import ArgumentParser, CliError, run

PARTS = ("ch7", "ch6", "map", "dob", "phantom")
#: busy processes of one recorded graph run: the composed loop and the recorder
GRAPH_RUN_PROCESSES = 2
QUICK_CONTROLLERS = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
QUICK_WALLS = [800.0]
QUICK_DURATION_S = 20.0
#: stability map: Kf values (B = 0) and the Z-width's wall dampings (N s/m)
MAP_KFS = [0.5, 1.0, 2.0, 5.0, 10.0, 25.0, 100.0]
ZWIDTH_CONTROLLERS = [("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)]
ZWIDTH_DAMPINGS = [0.0, 0.25, 0.5, 1.0]


def _say(text: str) -> None:
    print(text, flush=True)


def _parts(text: str) -> list[str]:
    parts = [p.strip() for p in text.split(",") if p.strip()]
    bad = [p for p in parts if p not in PARTS]
    if bad or not parts:
        raise CliError(f"--parts takes a comma-separated subset of {','.join(PARTS)}, got {text!r}")
    return parts


def _cached(path: Path, compute: Any) -> Any:
    """Batch results are kept in ``path`` (JSON) so that a resumed experiment skips them."""
    if path.is_file():
        return json.loads(path.read_text(encoding="utf-8"))
    value = compute()
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(json.dumps(value, indent=1) + "\n", encoding="utf-8")
    return value


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
    from haptic_dob.configs import resolve_config
    from haptic_dob.runtime.cpus import free_cpus, workers_for
    from haptic_sim.experiments import graph_runs, plan, report, results
    from haptic_sim.session import SessionConfig

    if workers is not None and workers < 1:
        raise CliError(f"--workers must be >= 1, got {workers}")
    if seed < 0:
        raise CliError(f"--seed must be >= 0, got {seed}")
    parts = ["ch7"] if quick else _parts(parts_text)
    config_path = resolve_config(config)
    root = Path(out)
    if fresh and root.exists():
        if not (root / "results.json").is_file() and not (root / "runs").is_dir():
            raise CliError(f"--fresh: {root} does not look like an experiment directory")
        shutil.rmtree(root)
    root.mkdir(parents=True, exist_ok=True)
    (root / "figures").mkdir(exist_ok=True)
    base = SessionConfig.from_yaml(config_path)
    t_start = time.monotonic()
    timing: dict[str, float] = {}
    res: dict[str, Any] = {
        "config": str(config),
        "config_params": graph_runs.session_params(config_path, {}),
        "quick": quick,
        "seed": seed,
        "parts": parts,
    }
    if workers is None:
        free = free_cpus()
        graph_workers, batch_workers = workers_for(GRAPH_RUN_PROCESSES, free), workers_for(1, free)
        basis = f"{free:.1f} CPUs free"
    else:
        graph_workers = batch_workers = workers
        basis = "--workers"
    _say(
        f"haptic-experiment: {', '.join(parts)} -> {root}/ ({graph_workers} graph run(s) and "
        f"{batch_workers} batch job(s) at a time: {basis})"
    )

    # --- batch parts first (they use every core for a short while) -----------------------------
    batch = [p for p in parts if p in ("map", "dob", "phantom")]
    if batch:
        with ProcessPoolExecutor(batch_workers) as ex:
            if "map" in parts:
                t0 = time.monotonic()
                res["map"] = _cached(root / "batch" / "map.json", lambda: _map(base, ex))
                timing["map"] = time.monotonic() - t0
                _say(f"stability map: {len(res['map'])} onsets ({timing['map']:.0f} s)")
            if "dob" in parts:
                t0 = time.monotonic()
                res["dob"] = _cached(root / "batch" / "dob.json", lambda: _dob(base, ex))
                timing["dob"] = time.monotonic() - t0
                _say(f"DOB mechanism study: done ({timing['dob']:.0f} s)")
        if "phantom" in parts:
            from haptic_sim.thesis52 import reproduce_free_motion, reproduce_wall

            t0 = time.monotonic()
            figs = root / "figures"
            res["phantom"] = _cached(
                root / "batch" / "phantom.json",
                lambda: {
                    "5.2.1": reproduce_free_motion(figs),
                    "5.2.2": reproduce_wall(figs),
                },
            )
            timing["phantom"] = time.monotonic() - t0
            _say(f"PHANToM section 5.2: done ({timing['phantom']:.0f} s)")
        if "dob" in parts and not (root / "figures" / "dob_kick_traces.png").is_file():
            from haptic_sim.experiments import dob

            dob.plot_traces(
                dob.traces(base, 1600.0), 1600.0, root / "figures" / "dob_kick_traces.png"
            )

    # --- graph runs -----------------------------------------------------------------------------
    runs = []
    if "ch7" in parts:
        if quick:
            runs += plan.chapter7_runs(
                config_path, seed, QUICK_DURATION_S, QUICK_CONTROLLERS, QUICK_WALLS
            )
        else:
            runs += plan.chapter7_runs(config_path, seed)
    if "ch6" in parts:
        runs += plan.chapter6_runs(config_path)
    if runs:
        t0 = time.monotonic()
        sim = sum(r.duration_s for r in runs)
        _say(f"{len(runs)} node-graph runs ({sim:g} s simulated), {graph_workers} at a time")
        try:
            graph_runs.execute_all(root, runs, graph_workers, rtf_guess=1.0, progress=_say)
        except RuntimeError as exc:
            raise CliError(str(exc).splitlines()[0] + " (see its launch.log)") from None
        timing["graph_runs"] = time.monotonic() - t0
        t0 = time.monotonic()
        with ProcessPoolExecutor(batch_workers) as ex:
            rows = list(ex.map(results.analyse_run, [root] * len(runs), runs))
        timing["analysis"] = time.monotonic() - t0
        _say(f"analysed {len(rows)} bags ({timing['analysis']:.0f} s)")
        res["ch7"] = [r for r in rows if r["part"] == "ch7"]
        res["ch6"] = [r for r in rows if r["part"] == "ch6"]
        res["ch7_checks"] = results.ch7_checks(res["ch7"])
        if res["ch6"]:
            res["ch6_onsets"] = results.ch6_onsets(res["ch6"])
            res["ch6_checks"] = results.ch6_checks(
                res["ch6_onsets"], base.model.viscous_n_s_per_m, base.loop.rate_hz
            )
    timing["total"] = time.monotonic() - t_start
    res["timing_s"] = timing
    (root / "results.json").write_text(json.dumps(res, indent=1) + "\n", encoding="utf-8")
    path = report.write(root, res, base)
    _say(report.console_summary(res))
    _say(f"report: {path} (total {timing['total']:.0f} s)")
    return 0


def _map(base: Any, executor: Any) -> list[dict]:
    from haptic_sim.experiments.zwidth import stability_map

    controllers = [("OL", 0.0)] + [(m, kf) for m in ("CL", "DOB") for kf in MAP_KFS]
    points = stability_map(controllers, [0.0], base, executor=executor)
    extra = stability_map(
        ZWIDTH_CONTROLLERS, [d for d in ZWIDTH_DAMPINGS if d != 0.0], base, executor=executor
    )
    return [p.as_dict() for p in points + extra]


def _dob(base: Any, executor: Any) -> dict[str, Any]:
    from haptic_sim.experiments import dob

    kick = dob.kick_grid(base, executor=executor)
    return {
        "kick": dob.as_dicts(kick),
        "first_vibrating": [
            {"gain": c, "coulomb_n": fc, "wall": dob.first_vibrating(kick, c, fc)}
            for c, fc in dob.KNOBS
        ],
        "linear": dob.linear_onsets(base, [2.0, 10.0, 41.6], [1.0, 2.0, 25.0, 100.0]),
        "bandwidth_vs_gain": dob.bandwidth_vs_gain(
            base, dob.GAINS_FOR_BANDWIDTH, executor=executor
        ),
        "model_mismatch": dob.model_mismatch(base, executor=executor),
    }


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
        f"at the start: {GRAPH_RUN_PROCESSES} per graph run, 1 per batch job)",
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
