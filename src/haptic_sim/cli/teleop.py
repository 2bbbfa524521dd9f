"""``haptic-teleop``: a simulated teleoperation session in batch, its figures, and the loop's
stability against the channel's delay.

Runs the session a teleoperation YAML describes (default ``teleop_sim``: the slide as master,
the 7-DOF arm pressing on a table as slave, its contact force estimated without a sensor) and
prints its figures (``haptic_sim.teleop.result``); ``--json`` prints them as one line. ``--out``
writes the force-tracking figure; ``--sweep`` runs the push-hold-pulse protocol over round-trip
delays with and without passivity control and adds the stability figure.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import math
import os
import sys
from pathlib import Path
from typing import Any

import yaml

from haptic_dob.cli.common import ArgumentParser, parse_range, run
from haptic_dob.core.observers.factory import OBSERVER_KINDS
from haptic_dob.errors import InputError
from haptic_dob.runtime.configs import resolve_config
from haptic_dob.teleop.settings import ARCHITECTURES, FORCE_SOURCES
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.result import TeleopMetrics, TeleopResult
from haptic_sim.teleop.session import run_teleop
from haptic_sim.teleop.stability import DelayPoint, DelayProtocol, boundary_ms, delay_sweep


def parse_set(item: str) -> tuple[str, str, Any]:
    """``SECTION:PARAM=VALUE`` (VALUE in YAML) -> (section, param, value)."""
    section, sep, assignment = item.partition(":")
    param, eq, text = assignment.partition("=")
    if not (sep and eq and section.startswith("/") and param):
        raise InputError(
            f"--set needs SECTION:PARAM=VALUE (e.g. /master/device_node:seed=3), got {item!r}"
        )
    try:
        return section, param, yaml.safe_load(text)
    except yaml.YAMLError:
        raise InputError(f"--set {item!r}: the value is not valid YAML") from None


def configure(
    config: str,
    sets: list[str],
    architecture: str | None,
    force_source: str | None,
    delay_ms: float | None,
    jitter_ms: float | None,
    passivity: bool | None,
    observer: str | None,
    duration_s: float | None,
) -> TeleopConfig:
    """The config file with the options applied (``ValueError``/``InputError`` on bad input)."""
    changes: dict[str, dict[str, Any]] = {}
    channel = changes.setdefault("/**/channel_node", {})
    for key, value in (
        ("teleop.architecture", architecture),
        ("teleop.force_source", force_source),
        ("channel.round_trip_delay_ms", delay_ms),
        ("channel.jitter_ms", jitter_ms),
        ("channel.passivity", passivity),
    ):
        if value is not None:
            channel[key] = value
    if observer is not None:
        changes["/slave/observer_node"] = {"kind": observer}
    if duration_s is not None:
        changes["/**/device_node"] = {"duration_s": duration_s}
    for item in sets:
        section, param, value = parse_set(item)
        changes.setdefault(section, {})[param] = value
    return TeleopConfig.from_yaml(resolve_config(config)).override(changes)


def format_metrics(m: TeleopMetrics) -> str:
    """The figures as a two-column table."""
    rows = [
        ("architecture", m.architecture),
        ("force sent back", m.force_source),
        ("round-trip delay", f"{m.round_trip_delay_ms:g} ms"),
        ("passivity control", "on" if m.passivity else "off"),
        ("duration", f"{m.duration_s:g} s"),
        ("in contact", f"{m.contact_pct:.1f} %"),
        ("contact force RMS", f"{m.contact_force_rms_n:.2f} N"),
        ("estimate error (contact)", f"{m.estimate_error_n:.2f} N  ({m.estimate_error_pct:.1f} %)"),
        ("force tracking error", f"{m.force_tracking_error_pct:.1f} %"),
        ("largest free estimate", f"{m.free_estimate_max_n:.2f} N"),
        ("position error (free)", f"{m.position_error_mm:.2f} mm"),
        ("channel energy, lowest", f"{m.channel_energy_min_j:.4f} J"),
        ("channel energy, final", f"{m.channel_energy_final_j:.4f} J"),
        ("dissipated by TDPA", f"{m.dissipated_j:.4f} J"),
        ("master oscillation", f"{m.oscillation_mm:.3f} mm"),
    ]
    return "\n".join(f"{k:<26} {v}" for k, v in rows)


def format_sweep(points: list[DelayPoint], threshold_mm: float) -> str:
    """The delay sweep as a table, with the boundary of each channel."""
    lines = [
        f"{'delay (ms)':>10} {'TDPA':>5} {'osc (mm)':>9} {'E min (J)':>10} {'diss (J)':>9}  stable"
    ]
    for p in points:
        lines.append(
            f"{p.round_trip_delay_ms:10g} {'on' if p.passivity else 'off':>5} "
            f"{p.oscillation_mm:9.3f} {p.channel_energy_min_j:10.3f} {p.dissipated_j:9.3f}  "
            f"{'yes' if p.stable else 'no'}"
        )
    for passivity in sorted({p.passivity for p in points}):
        b = boundary_ms(points, passivity)
        name = "TDPA" if passivity else "plain channel"
        lines.append(
            f"{name}: {'stable at every delay' if b is None else f'unstable from {b:g} ms'} "
            f"(oscillation threshold {threshold_mm:g} mm)"
        )
    return "\n".join(lines)


#: options that configure a run: not for ``--bag`` (the bag says how its session ran)
RUN_OPTIONS = {
    "config": "CONFIG",
    "architecture": "--architecture",
    "force_source": "--force-source",
    "delay_ms": "--delay-ms",
    "jitter_ms": "--jitter-ms",
    "passivity": "--passivity",
    "observer": "--observer",
    "duration": "--duration",
    "set": "--set",
    "sweep": "--sweep",
}


def bag_command(args: Any) -> int:
    """``--bag``: the figures (and ``--out``: the force-tracking figure) of a recorded graph."""
    from haptic_sim.teleop.bag import read_teleop_bag  # lazy: rosbags only for --bag

    given = [flag for name, flag in RUN_OPTIONS.items() if getattr(args, name) not in (None, [])]
    if given:
        raise InputError(
            f"{', '.join(given)}: not with --bag (the bag's parameters say how its session ran)"
        )
    out = Path(args.out) if args.out else None
    session = read_teleop_bag(args.bag)
    if session.samples_missing:
        print(
            f"note: {session.samples_missing} sample(s) missing on some topic, left out",
            file=sys.stderr,
        )
    return report(session.result.metrics(), [], session.result if out else None, out, args.json)


def report(
    metrics: TeleopMetrics,
    points: list[DelayPoint],
    result: TeleopResult | None,
    out: Path | None,
    as_json: bool,
) -> int:
    """Print the figures (and the sweep's); write the force-tracking figure of ``result``."""
    if out is not None and result is not None:
        # lazy: the figures' modules (matplotlib, the report's) only with --out
        from haptic_sim.teleop.figures import plot_force_tracking

        out.mkdir(parents=True, exist_ok=True)
        plot_force_tracking(result, out / "force_tracking.png")
    if as_json:
        doc: dict[str, Any] = dataclasses.asdict(metrics)
        if points:
            doc["sweep"] = [dataclasses.asdict(p) for p in points]
        print(json.dumps(_no_nan(doc), allow_nan=False))
    else:
        print(format_metrics(metrics))
        if points:
            print()
            print(format_sweep(points, DelayProtocol().threshold_mm))
    if out is not None:
        print(f"figures in {out}", file=sys.stderr)
    return 0


def command(args: Any) -> int:
    """Run what ``args`` ask for; raises on bad input."""
    if args.bag:
        return bag_command(args)
    cfg = configure(
        args.config or "teleop_sim",
        args.set,
        args.architecture,
        args.force_source,
        args.delay_ms,
        args.jitter_ms,
        args.passivity,
        args.observer,
        args.duration,
    )
    delays = parse_range(args.sweep, "--sweep") if args.sweep else None
    out = Path(args.out) if args.out else None
    if out is not None:
        out.mkdir(parents=True, exist_ok=True)
    result = run_teleop(cfg)
    points: list[DelayPoint] = []
    protocol = DelayProtocol()
    if delays is not None:
        points = delay_sweep(cfg, delays, protocol, workers=max(1, args.workers))
        if out is not None:
            # lazy: the figures' modules (matplotlib, the report's) only with --out
            from haptic_sim.teleop.figures import plot_delay_sweep

            plot_delay_sweep(points, protocol.threshold_mm, out / "stability.png")
    return report(result.metrics(), points, result, out, args.json)


def _no_nan(value: Any) -> Any:
    """``value`` with NaN (a figure without data: no contact, say) as None, for JSON."""
    if isinstance(value, float) and not math.isfinite(value):
        return None
    if isinstance(value, dict):
        return {k: _no_nan(v) for k, v in value.items()}
    if isinstance(value, list):
        return [_no_nan(v) for v in value]
    return value


def build_parser() -> ArgumentParser:
    """The command line of ``haptic-teleop``."""
    p = ArgumentParser(prog="haptic-teleop", description=__doc__.split("\n\n")[0])
    p.add_argument("config", nargs="?", help="teleoperation YAML (default teleop_sim)")
    p.add_argument(
        "--bag",
        metavar="BAG",
        help="analyse a recorded teleoperation graph (haptic-launch teleop_sim --record BAG) "
        "instead of running one: its figures, and with --out its force-tracking figure",
    )
    p.add_argument("--architecture", choices=ARCHITECTURES, help="what the master renders")
    p.add_argument(
        "--force-source", choices=FORCE_SOURCES, help="the slave force sent back (position_force)"
    )
    p.add_argument("--delay-ms", type=float, metavar="MS", help="round-trip delay of the channel")
    p.add_argument("--jitter-ms", type=float, metavar="MS", help="largest extra one-way delay")
    p.add_argument(
        "--passivity",
        action=argparse.BooleanOptionalAction,
        help="time-domain passivity control on the channel (--no-passivity: off)",
    )
    p.add_argument("--observer", choices=OBSERVER_KINDS, help="the slave's observer")
    p.add_argument("--duration", type=float, metavar="S", help="session length (s)")
    p.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="SECTION:PARAM=VALUE",
        help="set a parameter of a config section, e.g. /master/device_node:seed=3 (repeatable)",
    )
    p.add_argument("--out", metavar="DIR", help="write the figures here")
    p.add_argument(
        "--sweep",
        metavar="FROM:TO:STEP",
        help="also run the stability protocol over these round-trip delays (ms), with and "
        "without passivity control",
    )
    p.add_argument("--workers", type=int, default=os.cpu_count() or 1, help="parallel sweep runs")
    p.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    return p


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-teleop``."""
    args = build_parser().parse_args(argv)
    return run(lambda: command(args))


if __name__ == "__main__":
    sys.exit(main())
