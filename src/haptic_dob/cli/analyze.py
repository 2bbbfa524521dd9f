"""``haptic-analyze BAG...``: transparency, vibration and energy of recorded sessions.

Reads rosbag2 bags (MCAP or sqlite3; from ``haptic-record`` or ``ros2 bag record``), splits each
into segments where the recorded parameters change, and reports per segment: transparency
bandwidth and impedance error (H1, Welch), coherence, contact, vibration and the largest
energy the device delivered to the hand. Several bags add a summary in the shape of the
thesis's Tables 7.1 and 7.2.
"""

from __future__ import annotations

import os
import sys
from collections.abc import Sequence

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.errors import InputError


def _band(text: str) -> tuple[float, float]:
    try:
        lo, hi = (float(p) for p in text.split(":"))
    except ValueError:
        raise InputError(f"--vibration-band must be LO:HI in Hz, got {text!r}") from None
    return lo, hi


def command(
    bags: Sequence[str],
    motion_topic: str,
    force_topic: str,
    axis: str,
    joint: str | None,
    stiffness: float | None,
    fmax: float,
    settle: float,
    transient: float,
    vibration_band: str,
    vibration_threshold: float,
    output: str,
    plot_dir: str | None,
) -> int:
    """Analyse ``bags`` and print the chosen output; raises ``BagError``/``ValueError``."""
    # lazy: --help and bad arguments answer before numpy, scipy and rosbags load
    from haptic_dob.analysis.oscillation import OscillationSettings
    from haptic_dob.bag.analyze import AnalysisSettings, analyze_bag
    from haptic_dob.bag.reader import Selection
    from haptic_dob.bag.report import as_csv, as_json, summary, table

    sel = Selection(motion_topic, force_topic, axis, joint)
    settings = AnalysisSettings(
        fmax_hz=fmax,
        settle_s=settle,
        transient_s=transient,
        stiffness_n_per_m=stiffness,
        oscillation=OscillationSettings(
            band_hz=_band(vibration_band), threshold_m=vibration_threshold
        ),
    )
    analyses = [analyze_bag(b, sel, settings) for b in bags]
    if output == "json":
        text = as_json(analyses) + "\n"
    elif output == "csv":
        text = as_csv(analyses)
    else:
        text = table(analyses) + "\n"
        if len(analyses) > 1:
            text += "\n" + summary(analyses) + "\n"
    try:
        sys.stdout.write(text)
        sys.stdout.flush()
    except BrokenPipeError:  # the reader went away (``| head``): not an error of ours
        os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
    if plot_dir is not None:
        from haptic_dob.bag.plots import write_plots  # lazy: matplotlib only with --plot

        files = write_plots(analyses, plot_dir)
        print(f"wrote {len(files)} figure(s) to {plot_dir}", file=sys.stderr)
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-analyze``."""
    p = ArgumentParser(prog="haptic-analyze", description=__doc__.split("\n\n")[0])
    p.add_argument("bags", nargs="+", metavar="BAG", help="bag directory or .mcap/.db3 file")
    p.add_argument(
        "--motion-topic",
        default="ee_pose",
        metavar="TOPIC",
        help="PoseStamped (the --axis coordinate) or JointState (first joint or --joint); "
        "default ee_pose",
    )
    p.add_argument(
        "--force-topic",
        default="wrench_measured",
        metavar="TOPIC",
        help="WrenchStamped hand force (the --axis component); default wrench_measured",
    )
    p.add_argument("--axis", choices=["x", "y", "z"], default="x", help="default x")
    p.add_argument("--joint", metavar="NAME", help="joint of a JointState motion topic")
    p.add_argument(
        "--stiffness",
        type=float,
        metavar="N_PER_M",
        help="desired stiffness K (N/m), overriding the recorded wall stiffness",
    )
    p.add_argument(
        "--fmax", type=float, default=10.0, metavar="HZ", help="highest frequency (default 10)"
    )
    p.add_argument(
        "--settle",
        type=float,
        default=2.0,
        metavar="S",
        help="left out at the start of a session, the hand's ramp-in (default 2)",
    )
    p.add_argument(
        "--transient",
        type=float,
        default=0.5,
        metavar="S",
        help="left out after each parameter change (default 0.5)",
    )
    p.add_argument(
        "--vibration-band",
        default="10:200",
        metavar="LO:HI",
        help="band of the vibration detector in Hz (default 10:200)",
    )
    p.add_argument(
        "--vibration-threshold",
        type=float,
        default=2e-5,
        metavar="M",
        help="smallest vibration amplitude that counts (m, default 2e-5)",
    )
    fmt = p.add_mutually_exclusive_group()
    fmt.add_argument("--json", action="store_true", help="one JSON object per segment")
    fmt.add_argument("--csv", action="store_true", help="CSV, one row per segment")
    p.add_argument("--plot", metavar="DIR", help="write PNG figures of every segment into DIR")
    a = p.parse_args(argv)
    output = "json" if a.json else "csv" if a.csv else "table"
    return run(
        lambda: command(
            a.bags,
            a.motion_topic,
            a.force_topic,
            a.axis,
            a.joint,
            a.stiffness,
            a.fmax,
            a.settle,
            a.transient,
            a.vibration_band,
            a.vibration_threshold,
            output,
            a.plot,
        )
    )


if __name__ == "__main__":
    sys.exit(main())
