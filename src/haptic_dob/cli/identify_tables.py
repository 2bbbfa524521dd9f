"""``haptic-identify``'s outputs: its tables and the model's params file."""

from __future__ import annotations

from collections.abc import Mapping

from haptic_dob.identification.arm_friction import ArmFrictionFit
from haptic_dob.identification.filters import plus_minus
from haptic_dob.identification.one_dof import SlideFit
from haptic_dob.identification.per_axis import AxesFit
from haptic_dob.runtime.params_file import dump_params

#: why a fit has no Coulomb friction: the step method separates it from the swings' decay only
#: where the effort holds the rendered spring (it then falls back to the thesis's formulas)
NO_COULOMB = {
    "step": "- (the effort holds no spring: the thesis's formulas, friction read as damping)",
    "thesis_step": "- (the thesis's formulas leave it out)",
}


def table(fit: SlideFit, bag: str) -> str:
    """The fit as a short table (units in the row names)."""
    no_fc = NO_COULOMB.get(fit.method, "-")
    rows = [
        f"bag {bag}, joint {fit.joint}, method {fit.method}, {fit.samples} samples",
        f"mass_kg              {plus_minus(fit.mass_kg, fit.mass_std, '.4f')}",
        f"viscous_n_s_per_m    {plus_minus(fit.viscous_n_s_per_m, fit.viscous_std, '.4f')}",
        f"coulomb_n            {plus_minus(fit.coulomb_n, fit.coulomb_std, '.4f', no_fc)}",
    ]
    if fit.rms_residual_n is not None:
        rows.append(f"rms residual (N)     {fit.rms_residual_n:.4f}")
    return "\n".join(rows)


#: the nodes that assume a model of the device (the device node keeps its own physics)
MODEL_NODES = ("observer_node", "controller_node")


def model_yaml(params: Mapping[str, object], what: str, bag: str) -> str:
    """A params file that sets ``params`` of the observer's and the controller's model
    (``dump_params``: a list both share is written twice, never as an alias rcl refuses)."""
    head = f"# identified from {bag} by haptic-identify ({what})\n"
    doc = {f"/**/{n}": {"ros__parameters": dict(params)} for n in MODEL_NODES}
    return head + dump_params(doc)


def arm_table(fit: ArmFrictionFit, bag: str) -> str:
    """Each joint's friction and what it explains on the held-out part of the record."""
    held = round(100 * fit.holdout)
    rows = [
        f"bag {bag}: joint friction beyond the URDF's rigid body (held out: the last {held} %)",
        "joint                viscous (N m s/rad)   Coulomb (N m)       turns over (rad/s)  "
        "held-out RMS (N m): rigid -> with friction",
    ]
    for j in fit.joints:
        turn = f"{j.coulomb_speed:.4g}" if j.coulomb_speed > 0.0 else "- (a sign)"
        rows.append(
            f"{j.joint:<20} {plus_minus(j.viscous, j.viscous_std, '.4f'):<21} "
            f"{plus_minus(j.coulomb, j.coulomb_std, '.4f'):<19} {turn:<19} "
            f"{j.heldout_rms_rigid:.4f} -> {j.heldout_rms:.4f}"
        )
    return "\n".join(rows)


def axes_table(fit: AxesFit, bag: str) -> str:
    """Each axis's mass, viscous and Coulomb friction with standard errors (least squares)."""
    rows = [
        f"bag {bag}: each axis by least squares",
        "axis         mass (kg)            viscous (N s/m)      Coulomb (N)          samples  "
        "rms residual (N)",
    ]
    for f in fit.axes:
        rows.append(
            f"{f.joint:<12} {plus_minus(f.mass_kg, f.mass_std, '.4f'):<20} "
            f"{plus_minus(f.viscous_n_s_per_m, f.viscous_std, '.4f'):<20} "
            f"{plus_minus(f.coulomb_n, f.coulomb_std, '.4f'):<20} {f.samples:<8} "
            f"{f.rms_residual_n or 0.0:.4f}"
        )
    return "\n".join(rows)
