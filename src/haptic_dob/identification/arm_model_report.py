"""What an arm's identification found (``arm_model``): typed, as a table, as JSON, as a URDF."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from haptic_dob.identification.arm_consistent import (
    ConsistentFit,
    Link,
    inertia_about_com,
    pseudo_inertia,
)
from haptic_dob.identification.arm_urdf import JointDynamics, LinkInertial, rewrite_urdf

Triple = tuple[float, float, float]


Arr = NDArray[np.float64]


@dataclass(frozen=True)
class LinkFit:
    """A body's child link as identified (link frame; kg, m, kg m^2) beside its CAD values, the
    box its centre of mass was held in and its pseudo-inertia's smallest eigenvalue (> 0)."""

    link: str
    mass: float
    com: Triple
    inertia: tuple[float, float, float, float, float, float]  # about the COM: xx xy xz yy yz zz
    cad_mass: float
    cad_com: Triple
    box_lo: Triple
    box_hi: Triple
    pseudo_inertia_min: float

    def inertial(self) -> LinkInertial:
        """As a URDF ``<inertial>``."""
        xx, xy, xz, yy, yz, zz = self.inertia
        tensor = np.array([[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]])
        return LinkInertial(self.mass, np.array(self.com), tensor)


@dataclass(frozen=True)
class JointFit:
    """A joint's identified armature (kg m^2), viscous (N m s/rad) and Coulomb (N m) friction
    and the speed the latter turns over (rad/s, 0: a sign); on the held-out part, the RMS of the
    effort the identified and the CAD model leave (N m) and the effort's span (N m)."""

    joint: str
    armature: float
    viscous: float
    coulomb: float
    coulomb_speed: float
    heldout_rms: float
    heldout_rms_cad: float
    torque_span: float

    def dynamics(self) -> JointDynamics:
        """As URDF ``<dynamics>`` (and ``<haptic_dob:dynamics>``)."""
        return JointDynamics(self.viscous, self.coulomb, self.coulomb_speed, self.armature)


@dataclass(frozen=True)
class ArmModelFit:
    """The identified model and how well it does (see ``arm_model``).

    ``unidentifiable``: the standard parameters outside the base set (the data see them only
    combined with others, or not at all: held toward CAD); ``visibility``: each base
    parameter's (1: as well seen as by motion across the joints' ranges).
    """

    links: tuple[LinkFit, ...]
    joints: tuple[JointFit, ...]
    holdout: float
    samples: int  # fitted (decimated) samples
    condition_number: float  # the base regressor's, columns scaled to unit norm
    visibility: tuple[tuple[str, float], ...]
    unidentifiable: tuple[str, ...]

    @property
    def residual_pct(self) -> float:
        """The worst joint's held-out RMS residual, % of its torque span."""
        return max(100.0 * j.heldout_rms / j.torque_span for j in self.joints)

    @property
    def residual_cad_pct(self) -> float:
        """The same with the CAD model."""
        return max(100.0 * j.heldout_rms_cad / j.torque_span for j in self.joints)

    def urdf(self, cad_urdf: str, note: str) -> str:
        """``cad_urdf`` (XML or a path) with the identified ``<inertial>`` and dynamics."""
        return rewrite_urdf(
            cad_urdf,
            {lf.link: lf.inertial() for lf in self.links},
            {j.joint: j.dynamics() for j in self.joints},
            note,
        )

    def as_json(self) -> dict[str, Any]:
        """Plain values (lists, floats) with the worst residuals."""
        out = dataclasses.asdict(self)
        out["residual_pct"] = self.residual_pct
        out["residual_cad_pct"] = self.residual_cad_pct
        return out


def table(fit: ArmModelFit, bag: str) -> str:
    """The identified model as a short table (units in the headings)."""
    held = round(100 * fit.holdout)
    rows = [
        f"bag {bag}: the arm's model from {fit.samples} samples (held out: the last {held} %), "
        f"condition number {fit.condition_number:.3g}",
        "link                 mass (kg): CAD -> identified   COM (mm): CAD -> identified",
    ]
    for lf in fit.links:
        cad = ", ".join(f"{1e3 * c:.1f}" for c in lf.cad_com)
        com = ", ".join(f"{1e3 * c:.1f}" for c in lf.com)
        rows.append(
            f"{lf.link:<20} {lf.cad_mass:7.3f} -> {lf.mass:7.3f}          ({cad}) -> ({com})"
        )
    rows.append(
        "joint                armature (kg m^2)  viscous (N m s/rad)  Coulomb (N m)  turns over "
        "(rad/s)  held-out RMS % of span: CAD -> identified"
    )
    for j in fit.joints:
        turn = f"{j.coulomb_speed:.4g}" if j.coulomb_speed > 0.0 else "- (a sign)"
        rows.append(
            f"{j.joint:<20} {j.armature:<18.4g} {j.viscous:<20.4g} {j.coulomb:<14.4g} "
            f"{turn:<18} {100 * j.heldout_rms_cad / j.torque_span:6.2f} -> "
            f"{100 * j.heldout_rms / j.torque_span:.2f}"
        )
    rows.append(
        f"worst joint: {fit.residual_cad_pct:.2f} % of its torque span with CAD, "
        f"{fit.residual_pct:.2f} % identified"
    )
    if fit.unidentifiable:
        rows.append(
            f"not identifiable on their own (held toward CAD): {', '.join(fit.unidentifiable)}"
        )
    return "\n".join(rows)


def link_fit(name: str, link: Link, found: tuple[float, Arr, Arr]) -> LinkFit:
    """Link ``name``'s fitted mass, centre of mass and inertia beside its CAD values."""
    m, c, sigma = found
    inertia = inertia_about_com(sigma)
    xx, xy, xz = (float(v) for v in inertia[0])
    yy, yz, zz = float(inertia[1, 1]), float(inertia[1, 2]), float(inertia[2, 2])
    return LinkFit(
        link=name,
        mass=float(m),
        com=_triple(c),
        inertia=(xx, xy, xz, yy, yz, zz),
        cad_mass=link.mass,
        cad_com=_triple(link.com),
        box_lo=_triple(link.lo),
        box_hi=_triple(link.hi),
        pseudo_inertia_min=float(np.linalg.eigvalsh(pseudo_inertia(m, c, sigma))[0]),
    )


def _triple(v: Arr) -> tuple[float, float, float]:
    return (float(v[0]), float(v[1]), float(v[2]))


def joint_fits(
    joints: Sequence[str],
    found: ConsistentFit,
    speeds: Sequence[float],
    heldout: tuple[Arr, Arr, Arr],
) -> tuple[JointFit, ...]:
    """Each joint's friction, armature and held-out residual (``heldout``: the errors
    identified and CAD, and the torque spans)."""
    e, e_cad, span = heldout
    rms, rms_cad = np.sqrt(np.mean(e * e, axis=0)), np.sqrt(np.mean(e_cad * e_cad, axis=0))
    return tuple(
        JointFit(
            joint=name,
            armature=float(found.armature[j]),
            viscous=float(found.viscous[j]),
            coulomb=float(found.coulomb[j]),
            coulomb_speed=float(speeds[j]),
            heldout_rms=float(rms[j]),
            heldout_rms_cad=float(rms_cad[j]),
            torque_span=float(span[j]),
        )
        for j, name in enumerate(joints)
    )
