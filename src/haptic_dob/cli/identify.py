"""``haptic-identify BAG``: the 1-DOF device model (mass, viscous and Coulomb friction) from a bag.

Reads a recorded session's joint states (MCAP or sqlite3; ours or ``ros2 bag record``'s;
``/joint_states`` alone is enough) and identifies ``m x'' + c x' + Fc sgn(x') = u`` by least
squares (default) or by the step method under a virtual spring (``--method step``, or
``thesis_step`` for the thesis's formulas verbatim). ``--urdf FILE --tip-frame F``: an arm's
joint friction beyond the URDF's rigid body (``identification.arm_friction``); with
``--inertial``, the arm's whole physically consistent model (``identification.arm_model``),
written as a URDF by ``--write-urdf OUT``. ``--axes X,Y,Z``: a Cartesian device per axis
(``identification.per_axis``). ``--velocity-noise --counts C``: the bridge's Kalman velocity
filter (``cli.identify_velocity``). Prints a table, or one JSON line (``--json``);
``--write-yaml FILE`` writes the model as the observer's and controller's params file
(``slide.*``, ``point_mass.*`` or ``urdf.*`` friction; the bridge's for ``--velocity-noise``),
to load after the session's config.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

from haptic_dob.bag.joints import read_joint, read_joints
from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.cli.identify_tables import arm_table, axes_table, model_yaml, table
from haptic_dob.cli.identify_velocity import velocity_command
from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_urdf import read_urdf
from haptic_dob.errors import InputError
from haptic_dob.identification.arm_friction import identify_arm_friction
from haptic_dob.identification.arm_model import Record, identify_arm_model
from haptic_dob.identification.arm_model_report import table as model_table
from haptic_dob.identification.one_dof import METHODS, IdentificationError, identify
from haptic_dob.identification.per_axis import identify_axes
from haptic_dob.runtime.configs import config_dir


@dataclass(frozen=True)
class ArmSpec:
    """The arm whose friction is identified: URDF file, tip frame, joints (empty: the chain)."""

    urdf: str
    tip_frame: str
    joints: tuple[str, ...] = ()
    turn_cutoff_hz: float | None = None  # the search for v_c through this low-pass (Hz)
    inertial: bool = False  # the whole model, not only the friction


def installed_urdf(name: str) -> str:
    """``--urdf``: a file, or one the suite installs beside its configs (``urdf/
    phantom_omni.urdf``) when no such file is here."""
    if Path(name).is_file() or Path(name).is_absolute():
        return name
    beside = config_dir() / name
    return str(beside) if beside.is_file() else name


def arm_command(bag: str, topic: str, arm: ArmSpec, as_json: bool, write_yaml: str | None) -> int:
    """Identify an arm's joint friction, print it, optionally write it as the model's."""
    urdf = installed_urdf(arm.urdf)
    rigid = UrdfModel(urdf, arm.tip_frame, arm.joints or None, viscous=0.0, coulomb=0.0)
    js = read_joints(bag, topic, rigid.joint_names)
    try:
        fit = identify_arm_friction(
            rigid,
            js.stamps_ns,
            js.position,
            js.effort,
            js.names,
            turn_cutoff_hz=arm.turn_cutoff_hz,
        )
    except IdentificationError as exc:
        raise InputError(f"{bag}: {exc}") from None
    if as_json:
        print(json.dumps({"bag": bag, "joints": [j.__dict__ for j in fit.joints]}))
    else:
        print(arm_table(fit, bag))
    if write_yaml:
        text = model_yaml(fit.as_params(), f"joint friction, URDF {arm.urdf}", bag)
        Path(write_yaml).write_text(text, encoding="utf-8")
        if not as_json:
            print(f"model written to {write_yaml}")
    return 0


def inertial_command(
    bag: str, topic: str, arm: ArmSpec, as_json: bool, write_urdf: str | None
) -> int:
    """Identify an arm's whole model, print it, optionally write it back as a URDF."""
    urdf = installed_urdf(arm.urdf)
    cad = UrdfModel(urdf, arm.tip_frame, arm.joints or None)
    js = read_joints(bag, topic, cad.joint_names)
    record = Record(js.stamps_ns, js.position, js.effort, js.names)
    try:
        fit = identify_arm_model(
            read_urdf(urdf), arm.tip_frame, record, turn_cutoff_hz=arm.turn_cutoff_hz
        )
    except IdentificationError as exc:
        raise InputError(f"{bag}: {exc}") from None
    if as_json:
        print(json.dumps({"bag": bag, **fit.as_json()}))
    else:
        print(model_table(fit, bag))
    if write_urdf:
        note = f"identified from {bag} by haptic-identify, its inertial fit (URDF {arm.urdf})"
        Path(write_urdf).write_text(fit.urdf(urdf, note), encoding="utf-8")
        if not as_json:
            print(f"URDF written to {write_urdf}")
    return 0


def parse_axes(text: str) -> tuple[str, str, str]:
    """``--axes``: three different joint names, comma-separated, in x, y, z order."""
    names = tuple(n.strip() for n in text.split(","))
    if len(names) != 3 or not all(names) or len(set(names)) != 3:
        raise InputError(
            f"--axes needs three different joint names in x, y, z order (fd_x,fd_y,fd_z), "
            f"got {text!r}"
        )
    return names[0], names[1], names[2]


def axes_command(
    bag: str, topic: str, axes: tuple[str, ...], as_json: bool, write_yaml: str | None
) -> int:
    """Identify every axis of a Cartesian device, print, optionally write its point-mass model."""
    js = read_joints(bag, topic, axes)
    try:
        fit = identify_axes(js.stamps_ns, js.position, js.effort, js.names)
    except IdentificationError as exc:
        raise InputError(f"{bag}: {exc}") from None
    if as_json:
        print(json.dumps({"bag": bag, "axes": [f.__dict__ for f in fit.axes]}))
    else:
        print(axes_table(fit, bag))
    if write_yaml:
        text = model_yaml(fit.as_params(), f"point mass, axes {', '.join(axes)}", bag)
        Path(write_yaml).write_text(text, encoding="utf-8")
        if not as_json:
            print(f"model written to {write_yaml}")
    return 0


def command(
    bag: str, topic: str, joint: str | None, method: str, as_json: bool, write_yaml: str | None
) -> int:
    """Identify, print, optionally write the model; errors raise (``run`` reports them)."""
    rec = read_joint(bag, topic, joint)
    try:
        fit = identify(rec, method)
    except IdentificationError as exc:
        raise InputError(f"{bag}: {exc}") from None
    if as_json:
        out = {k: v for k, v in fit.__dict__.items()}
        out["bag"] = bag
        print(json.dumps(out))
    else:
        print(table(fit, bag))
    if write_yaml:
        what = f"{fit.method}, joint {fit.joint}"
        Path(write_yaml).write_text(model_yaml(fit.as_params(), what, bag), encoding="utf-8")
        if not as_json:
            print(f"model written to {write_yaml}")
    return 0


def main(argv: Sequence[str] | None = None) -> int:
    """Parse the command line and run."""
    p = ArgumentParser(prog="haptic-identify", description=__doc__.split("\n\n")[0])
    p.add_argument("bag", help="bag directory, .mcap or .db3 file")
    p.add_argument(
        "--topic", default="joint_states", help="JointState topic (default joint_states)"
    )
    p.add_argument("--joint", help="joint name (default: the first)")
    p.add_argument(
        "--method",
        choices=METHODS,
        default="least_squares",
        help="least_squares (any excitation, default); step (under a rendered spring: damping "
        "and Coulomb friction from the swings' decay); thesis_step (the thesis's formulas: "
        "the first overshoot, no Coulomb friction)",
    )
    p.add_argument("--json", action="store_true", help="one JSON line instead of the table")
    p.add_argument("--write-yaml", metavar="FILE", help="write the model as a params file")
    p.add_argument(
        "--urdf",
        metavar="FILE",
        help="an arm: identify its joint friction beyond this URDF (a path, or one the suite "
        "installs: urdf/phantom_omni.urdf)",
    )
    p.add_argument("--tip-frame", help="with --urdf: the arm's end-effector frame")
    p.add_argument(
        "--joints",
        help="with --urdf: comma-separated joints (default: the chain to the tip); the chain's "
        "other joints are taken as still at zero. With --velocity-noise: the joints to read "
        "(default: every joint of the first message)",
    )
    p.add_argument(
        "--turn-cutoff-hz",
        type=float,
        metavar="HZ",
        help="with --urdf: judge the speed the Coulomb friction turns over through this "
        "low-pass (default: the fit's 20 Hz); a wider one (e.g. 50) resolves a turn of a few "
        "milliseconds where the encoders resolve speeds well below it",
    )
    p.add_argument(
        "--inertial",
        action="store_true",
        help="with --urdf: the arm's whole model, not only its joint friction: every link's mass, "
        "centre of mass and inertia (physically consistent, drawn toward the URDF's where the bag "
        "does not see them), each joint's armature, viscous and Coulomb friction; a bag with too "
        "little excitation is refused, naming what it does not see",
    )
    p.add_argument(
        "--write-urdf",
        metavar="OUT",
        help="with --inertial: write the URDF with the identified <inertial> and <dynamics> "
        "(armature and Coulomb turn in <haptic_dob:dynamics>) for the observer's urdf_path",
    )
    p.add_argument(
        "--axes",
        metavar="X,Y,Z",
        help="a Cartesian device: identify each of these joints (x, y, z order; fd_x,fd_y,fd_z "
        "for a Force Dimension device) as an axis of the point-mass model, by least squares",
    )
    p.add_argument(
        "--velocity-noise",
        action="store_true",
        help="the bridge's Kalman velocity filter: its jerk density from a session with the hand "
        "moving the device (positions only), one for every joint that moved; needs --counts; "
        "--write-yaml writes the bridge's state.encoder_resolution and state.velocity_jerk_psd",
    )
    p.add_argument(
        "--counts",
        metavar="C[,C...]",
        help="with --velocity-noise: each joint's encoder count in the bag's units (one for all, "
        "or one per joint: the bridge's state.encoder_resolution)",
    )
    a = p.parse_args(argv)
    if a.velocity_noise:
        off = (
            ("--urdf", a.urdf),
            ("--tip-frame", a.tip_frame),
            ("--joint", a.joint),
            ("--turn-cutoff-hz", a.turn_cutoff_hz is not None),
            ("--inertial", a.inertial),
            ("--write-urdf", a.write_urdf),
            ("--axes", a.axes),
            ("--method", a.method != "least_squares"),
        )
        clash = [f for f, on in off if on]
        if clash:
            p.error(f"--velocity-noise fits the positions alone: leave out {', '.join(clash)}")
        if not a.counts:
            p.error("--velocity-noise needs --counts (the bridge's state.encoder_resolution)")
        chosen = tuple(j for j in (a.joints or "").split(",") if j)
        return run(lambda: velocity_command(a.bag, a.topic, chosen, a.counts, a.json, a.write_yaml))
    if a.counts:
        p.error("--counts goes with --velocity-noise")
    if a.axes is not None:
        given = (
            ("--urdf", a.urdf),
            ("--tip-frame", a.tip_frame),
            ("--joints", a.joints),
            ("--turn-cutoff-hz", a.turn_cutoff_hz is not None),
            ("--joint", a.joint),
            ("--inertial", a.inertial),
            ("--write-urdf", a.write_urdf),
        )
        clash = [f for f, on in given if on]
        if a.method != "least_squares":
            clash.append("--method")
        if clash:
            p.error(f"--axes fits each axis by least squares: leave out {', '.join(clash)}")
        return run(lambda: axes_command(a.bag, a.topic, parse_axes(a.axes), a.json, a.write_yaml))
    if a.turn_cutoff_hz is not None and not 0.0 < a.turn_cutoff_hz < float("inf"):
        p.error(f"--turn-cutoff-hz must be a positive number of Hz, got {a.turn_cutoff_hz:g}")
    if (a.inertial or a.write_urdf) and not a.urdf:
        p.error("--inertial and --write-urdf need --urdf")
    if a.write_urdf and not a.inertial:
        p.error("--write-urdf needs --inertial (the friction alone goes to --write-yaml)")
    if a.inertial and a.write_yaml:
        p.error(
            "--write-yaml is the friction fit's; with --inertial the model goes to --write-urdf"
        )
    if a.urdf:
        if not a.tip_frame:
            p.error("--urdf needs --tip-frame")
        joints = tuple(j for j in (a.joints or "").split(",") if j)
        arm = ArmSpec(a.urdf, a.tip_frame, joints, a.turn_cutoff_hz, a.inertial)
        if a.inertial:
            return run(lambda: inertial_command(a.bag, a.topic, arm, a.json, a.write_urdf))
        return run(lambda: arm_command(a.bag, a.topic, arm, a.json, a.write_yaml))
    if a.turn_cutoff_hz is not None:
        p.error("--turn-cutoff-hz needs --urdf")
    return run(lambda: command(a.bag, a.topic, a.joint, a.method, a.json, a.write_yaml))


if __name__ == "__main__":
    sys.exit(main())
