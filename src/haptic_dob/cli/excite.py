"""``haptic-excite --urdf FILE --tip-frame F --start Q --out TRAJ``: an excitation for an arm.

Designs a finite Fourier series per joint (``haptic_dob.identification.arm_excitation``) that
starts and ends each period at rest at ``--start``, minimising the condition number of the arm's
base regressor within its joint position limits (less ``--margin``), a share of its speed and
effort limits, an acceleration limit and a box for the tip, and writes it as a trajectory file
the slave controller plays (``slave.trajectory_path``). Record the arm playing it, then
``haptic-identify BAG --urdf FILE --tip-frame F --inertial``. Prints the design's figures, or
one JSON line (``--json``).
"""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Sequence

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.errors import InputError


def _floats(text: str, n: int | None, name: str) -> list[float]:
    try:
        out = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(f"{name} must be comma-separated numbers, got {text!r}") from None
    if n is not None and len(out) != n:
        raise InputError(f"{name} needs {n} numbers, got {len(out)}")
    return out


def command(a: argparse.Namespace, line: str) -> int:
    """Design, write (``line``, the command line, in the file), print; errors raise."""
    # lazy: --help and bad arguments answer before pinocchio and scipy load
    from haptic_dob.core.models import UrdfModel
    from haptic_dob.identification.arm_excitation import ExcitationLimits
    from haptic_dob.identification.arm_excitation_design import design_excitation

    args = vars(a)
    model = UrdfModel(args["urdf"], args["tip_frame"], _names(args["joints"]))
    start = _floats(args["start"], model.dof, "--start") if args["start"] else [0.0] * model.dof
    box = _floats(args["box"], 6, "--box") if args["box"] else None
    limits = ExcitationLimits(
        margin_rad=args["margin"],
        speed_share=args["speed_share"],
        max_speed_rad_s=args["max_speed"],
        max_accel_rad_s2=args["max_accel"],
        effort_share=args["effort_share"],
        box_lo=None if box is None else (box[0], box[1], box[2]),
        box_hi=None if box is None else (box[3], box[4], box[5]),
    )
    design = design_excitation(
        model,
        start,
        period_s=args["period"],
        harmonics=args["harmonics"],
        limits=limits,
        iterations=args["iterations"],
        seed=args["seed"],
    )
    design.excitation.save(args["out"], f"written by haptic-excite {line}")
    figures = {
        "out": args["out"],
        "joints": list(model.joint_names),
        "period_s": args["period"],
        "condition_number": design.condition_number,
        "start_condition_number": design.start_condition_number,
        "peak_speed_share": design.peak_speed_share,
        "peak_accel_share": design.peak_accel_share,
        "peak_effort_share": design.peak_effort_share,
        "tip_lo": list(design.tip_lo),
        "tip_hi": list(design.tip_hi),
    }
    if args["json"]:
        print(json.dumps(figures))
    else:
        print(
            f"{args['out']}: {model.dof} joints, period {args['period']:g} s, condition number "
            f"{design.condition_number:.3g} (the best random start's "
            f"{design.start_condition_number:.3g})\n"
            f"peaks: speed {100 * design.peak_speed_share:.0f} %, acceleration "
            f"{100 * design.peak_accel_share:.0f} %, effort {100 * design.peak_effort_share:.0f} % "
            "of their limits\n"
            f"tip from {[round(c, 3) for c in design.tip_lo]} to "
            f"{[round(c, 3) for c in design.tip_hi]} m"
        )
    return 0


def _names(text: str | None) -> list[str] | None:
    names = [j for j in (text or "").split(",") if j]
    return names or None


def main(argv: Sequence[str] | None = None) -> int:
    """Parse the command line and run."""
    p = ArgumentParser(prog="haptic-excite", description=__doc__.split("\n\n")[0])
    p.add_argument("--urdf", required=True, metavar="FILE", help="the arm's URDF")
    p.add_argument("--tip-frame", required=True, help="the arm's end-effector frame")
    p.add_argument("--joints", help="comma-separated joints (default: the chain to the tip)")
    p.add_argument("--start", help="comma-separated start posture, rad (default: zeros)")
    p.add_argument("--out", required=True, metavar="TRAJ", help="the trajectory file to write")
    p.add_argument("--period", type=float, default=10.0, help="period, s (default 10)")
    p.add_argument("--harmonics", type=int, default=5, help="harmonics per joint (default 5)")
    p.add_argument(
        "--margin", type=float, default=0.1, help="kept from position limits, rad (default 0.1)"
    )
    p.add_argument(
        "--speed-share", type=float, default=0.5, help="of each speed limit (default 0.5)"
    )
    p.add_argument("--max-speed", type=float, default=1.5, help="rad/s (default 1.5)")
    p.add_argument("--max-accel", type=float, default=6.0, help="rad/s^2 (default 6)")
    p.add_argument(
        "--effort-share", type=float, default=0.8, help="of each effort limit (default 0.8)"
    )
    p.add_argument(
        "--box",
        metavar="XMIN,YMIN,ZMIN,XMAX,YMAX,ZMAX",
        help="the box the tip stays in, base frame, m (default: anywhere)",
    )
    p.add_argument("--iterations", type=int, default=40, help="optimiser iterations (default 40)")
    p.add_argument("--seed", type=int, default=0, help="seed of the random starts (default 0)")
    p.add_argument("--json", action="store_true", help="one JSON line instead of the text")
    given = list(sys.argv[1:] if argv is None else argv)
    a = p.parse_args(given)
    for name in ("period", "speed_share", "max_speed", "max_accel", "effort_share"):
        if not getattr(a, name) > 0.0:
            p.error(f"--{name.replace('_', '-')} must be > 0")
    if not a.margin >= 0.0:
        p.error("--margin must be >= 0")
    return run(lambda: command(a, " ".join(given)))


if __name__ == "__main__":
    sys.exit(main())
