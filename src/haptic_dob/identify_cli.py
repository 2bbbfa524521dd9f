"""``haptic-identify BAG``: the 1-DOF device model (mass, viscous and Coulomb friction) from a bag.

Reads the joint states of a recorded session (MCAP or sqlite3; ours or ``ros2 bag record``'s;
``/joint_states`` alone is enough) and identifies ``m x'' + c x' + Fc sgn(x') = u`` by least
squares (default) or by the thesis's step method (``--method step``, under a virtual spring).
Prints a table, or one JSON line (``--json``); ``--write-yaml FILE`` writes the observer's model
as a params file (``slide.*`` of the observer and the controller, the nodes that assume a model)
to load after the session's config.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Sequence
from pathlib import Path

from haptic_dob.cli import ArgumentParser, CliError, run
from haptic_dob.identification import METHODS, IdentificationError, SlideFit


def _pm(value: float | None, std: float | None, fmt: str) -> str:
    if value is None:
        return "-"
    return f"{value:{fmt}}" + (f" +- {std:{fmt}}" if std is not None else "")


def table(fit: SlideFit, bag: str) -> str:
    """The fit as a short table (units in the row names)."""
    rows = [
        f"bag {bag}, joint {fit.joint}, method {fit.method}, {fit.samples} samples",
        f"mass_kg              {_pm(fit.mass_kg, fit.mass_std, '.4f')}",
        f"viscous_n_s_per_m    {_pm(fit.viscous_n_s_per_m, fit.viscous_std, '.4f')}",
        f"coulomb_n            {_pm(fit.coulomb_n, fit.coulomb_std, '.4f')}",
    ]
    if fit.rms_residual_n is not None:
        rows.append(f"rms residual (N)     {fit.rms_residual_n:.4f}")
    return "\n".join(rows)


#: the nodes that assume a model of the device (the device node keeps its own physics)
MODEL_NODES = ("observer_node", "controller_node")


def model_yaml(fit: SlideFit, bag: str) -> str:
    """A params file that sets the assumed slide model of the observer and the controller."""
    import yaml

    head = f"# identified from {bag} by haptic-identify ({fit.method}, joint {fit.joint})\n"
    doc = {f"/**/{n}": {"ros__parameters": fit.as_params()} for n in MODEL_NODES}
    body: str = yaml.safe_dump(doc, sort_keys=False)
    return head + body


def command(
    bag: str, topic: str, joint: str | None, method: str, as_json: bool, write_yaml: str | None
) -> int:
    """Identify, print, optionally write the model; errors raise (``run`` reports them)."""
    from haptic_dob.bag.joints import read_joint
    from haptic_dob.identification import identify

    rec = read_joint(bag, topic, joint)
    try:
        fit = identify(rec, method)
    except IdentificationError as exc:
        raise CliError(f"{bag}: {exc}") from None
    if as_json:
        out = {k: v for k, v in fit.__dict__.items()}
        out["bag"] = bag
        print(json.dumps(out))
    else:
        print(table(fit, bag))
    if write_yaml:
        Path(write_yaml).write_text(model_yaml(fit, bag), encoding="utf-8")
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
        help="least_squares (any excitation, default) or step (the thesis's method)",
    )
    p.add_argument("--json", action="store_true", help="one JSON line instead of the table")
    p.add_argument("--write-yaml", metavar="FILE", help="write the model as a params file")
    a = p.parse_args(argv)
    return run(lambda: command(a.bag, a.topic, a.joint, a.method, a.json, a.write_yaml))


if __name__ == "__main__":
    sys.exit(main())
