"""``haptic-stability``: vibration-onset stiffness of a virtual wall by batch simulation."""

from __future__ import annotations

import json
import os
import sys

from haptic_dob.cli.common import ArgumentParser, parse_range, run
from haptic_dob.core.control import ControlMode
from haptic_dob.core.observers.disturbance import DEFAULT_GAIN
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.runtime.configs import resolve_config
from haptic_sim.slide.session import SessionConfig
from haptic_sim.slide.stability import StabilityProtocol, StabilitySweep, law_for, sweep

DEFAULT_RANGE = "100:4000:100"


def command(
    controller: str,
    kf: float,
    observer_gain: float | None,
    output_limit: float,
    stiffness: str,
    coulomb_n: float,
    as_json: bool,
    workers: int,
    config: str | None = None,
) -> int:
    """Run the sweep and print the table or JSON; raises on bad input."""
    ks = parse_range(stiffness, "--stiffness")
    nonnegative("--kf", kf)
    nonnegative("--output-limit", output_limit)
    base = SessionConfig.from_yaml(resolve_config(config)) if config else SessionConfig()
    gain = base.observer.gain if observer_gain is None else observer_gain
    positive("--observer-gain", gain)
    base = base.replace(
        law=law_for(controller, kf, base.law.max_force_n),
        observer=ObserverSettings(gain, output_limit),
    )
    result = sweep(ks, base, StabilityProtocol(coulomb_n=coulomb_n), workers=workers)
    if as_json:
        print(json.dumps(result.as_dict(), indent=2))
    else:
        print(format_table(result))
    return 0


def format_table(result: StabilitySweep) -> str:
    """A readable table of the sweep with onset and theory bound."""
    lines = [
        f"controller {result.controller}  Kf {result.kf:g}  "
        f"observer gain {result.observer_gain:g} N s/m",
        f"{'K (N/m)':>9} {'growth (1/s)':>13} {'freq (Hz)':>10} {'amp (um)':>9}  vibrates",
    ]
    for p in result.points:
        note = " (before the pulse)" if p.vibrating_before_pulse else ""
        lines.append(
            f"{p.stiffness_n_per_m:9.0f} {p.growth_per_s:13.3f} {p.frequency_hz:10.1f} "
            f"{p.amplitude_m * 1e6:9.1f}  {'yes' if p.vibrates else 'no'}{note}"
        )
    onset = result.onset_stiffness_n_per_m
    lines.append(
        f"onset: {'none in range' if onset is None else f'{onset:.0f} N/m'}   "
        f"theory bound 2b/(T(1+Kf)): {result.theory_bound_n_per_m:.0f} N/m"
    )
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-stability``."""
    p = ArgumentParser(
        prog="haptic-stability",
        description="Sweep the wall stiffness in batch simulation and report the vibration onset "
        "(push-and-hold protocol: see docs/recording-and-analysis.md).",
    )
    p.add_argument(
        "--controller",
        default="OL",
        type=str.upper,
        choices=[m.value for m in ControlMode],
        help="control law (default OL)",
    )
    p.add_argument("--kf", type=float, default=0.0, help="force-feedback gain Kf (CL, DOB)")
    p.add_argument(
        "--observer-gain",
        type=float,
        default=None,
        help=f"observer gain c in N s/m (default: the --config's, else {DEFAULT_GAIN})",
    )
    p.add_argument(
        "--output-limit",
        type=float,
        default=4.0,
        help="observer output clip in N, 0 = none (default 4)",
    )
    p.add_argument(
        "--stiffness",
        default=DEFAULT_RANGE,
        metavar="FROM:TO:STEP",
        help=f"wall stiffnesses in N/m (default {DEFAULT_RANGE})",
    )
    p.add_argument(
        "--coulomb-n",
        type=float,
        default=0.0,
        help="Coulomb friction of plant and model during the sweep in N (default 0: "
        "linear in-contact onset)",
    )
    p.add_argument("--config", help="session YAML (ros__parameters) for the device and gains")
    p.add_argument(
        "--workers",
        type=int,
        default=os.cpu_count() or 1,
        help="parallel simulations (default: all cores)",
    )
    p.add_argument("--json", action="store_true", help="print JSON instead of the table")
    a = p.parse_args(argv)
    return run(
        lambda: command(
            a.controller,
            a.kf,
            a.observer_gain,
            a.output_limit,
            a.stiffness,
            a.coulomb_n,
            a.json,
            max(1, a.workers),
            a.config,
        )
    )


if __name__ == "__main__":
    sys.exit(main())
