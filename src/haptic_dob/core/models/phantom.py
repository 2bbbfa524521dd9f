"""The PHANToM 1.5 (thesis appendix B; theory.md section 5), computed with pinocchio.

Joints ``q = [phi1, phi2, phi3]`` (rad): phi1 base yaw about the vertical z axis, phi2 and phi3
the absolute elevations of link 1 (upper arm) and link 2 (crank), both driven at the base. Base
frame: z up, origin where the three joint axes meet. End-effector point at ``le4`` from the elbow::

    r = l1 cos phi2 - le4 cos phi3,   p = [r cos phi1, r sin phi1, l1 sin phi2 - le4 sin phi3]

``HOME = (0, 0, pi/2)``: upper arm horizontal, forearm hanging straight down. Dynamics of the
open tree ``q_t = S q = [q1, q2, q3 - q2, q3, q2 - q3]`` by pinocchio: ``D = S^T crba S``,
``C q' + G = S^T rnea(S q, S q', 0)``, ``J = J_t S``. Parameter sets (``PHANTOM_PARAMS``):
``appendix_b`` (Table B.1, links as thin bodies) and ``cavusoglu`` (Cavusoglu, Feygin and
Tendick 2002, the real PHANToM 1.5). The tree and the conversions: docs/design/arms.md.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.models._pinocchio import PinocchioModel
from haptic_dob.core.models._pinocchio_tree import TreeJoint, tree_model
from haptic_dob.core.validation import finite_scalar, nonnegative
from haptic_dob.runtime.params import param

#: the PHANToM's rest pose used as the default start: upper arm level, forearm hanging down
HOME = (0.0, 0.0, math.pi / 2)

#: S of theory.md section 5: tree coordinates from the three driven angles
TREE_MAP = (
    (1.0, 0.0, 0.0),
    (0.0, 1.0, 0.0),
    (0.0, -1.0, 1.0),
    (0.0, 0.0, 1.0),
    (0.0, 1.0, -1.0),
)


@dataclass(frozen=True)
class LinkParams:
    """One link: mass (kg), centre of mass along the link (m), inertia about it (kg m^2).

    ``inertia`` holds the principal moments about the centre of mass along the link, about the
    joint axis and about the third (perpendicular) axis.
    """

    mass_kg: float
    com_m: float
    inertia_kg_m2: tuple[float, float, float]

    def __post_init__(self) -> None:
        nonnegative("mass_kg", self.mass_kg)
        finite_scalar("com_m", self.com_m)
        for i, v in enumerate(self.inertia_kg_m2):
            nonnegative(f"inertia_kg_m2[{i}]", v)


@dataclass(frozen=True)
class PhantomParams:
    """Geometry and mass properties of a PHANToM (SI units; see the module docstring).

    ``l2_m`` is the crank's hinge of link 3 along ``(cos phi3, sin phi3)``; a negative value puts
    it on the forearm's side (the real device). ``link4.com_m`` is measured from the elbow along
    the forearm (toward the tip).
    """

    name: str
    base_inertia_kg_m2: float
    l1_m: float
    l2_m: float
    le4_m: float
    link1: LinkParams
    link2: LinkParams
    link3: LinkParams
    link4: LinkParams


def _rod(mass: float, com: float, inertia: float) -> LinkParams:
    """A thin link: ``inertia`` about both axes across it, none along it."""
    return LinkParams(mass, com, (0.0, inertia, inertia))


#: thesis Table B.1 (l4 = 0.221 m is the elbow-to-tip length le4)
APPENDIX_B = PhantomParams(
    name="appendix_b",
    base_inertia_kg_m2=0.0915,
    l1_m=0.178,
    l2_m=0.089,
    le4_m=0.221,
    link1=_rod(0.047, 0.112, 2.83e-4),
    link2=_rod(0.020, 0.0445, 3.17e-5),
    link3=_rod(0.034, 0.0785, 1.81e-4),
    link4=_rod(0.228, 0.127, 2.29e-3),
)


def cavusoglu_params() -> PhantomParams:
    """Cavusoglu, Feygin and Tendick (2002), PHANToM 1.5, in this module's convention.

    Their constants: l1 = 0.215, l2 = 0.170, l3 = 0.0325, l5 = -0.0368, l6 = 0.0527 m; masses
    a 0.0202, c 0.0249, be 0.2359, df 0.1906 kg; inertias (xx, yy, zz; 1e-4 kg m^2) a 0.4864 /
    0.001843 / 0.4864, c 0.959 / 0.959 / 0.0051, be 11.09 / 10.06 / 0.591, df 7.11 / 0.629 /
    6.246, base yy 11.87. Their x is the joint axis; the be and df inertias are about the joint
    origin, so the centre-of-mass inertia here is theirs minus the parallel-axis term.
    """
    e4 = 1e-4
    l1, l2, l3, l5, l6 = 0.215, 0.170, 0.0325, -0.0368, 0.0527
    ma, mc, mbe, mdf = 0.0202, 0.0249, 0.2359, 0.1906
    be = LinkParams(mbe, l5, (0.591 * e4, 11.09 * e4 - mbe * l5**2, 10.06 * e4 - mbe * l5**2))
    df = LinkParams(mdf, l6, (0.629 * e4, 7.11 * e4 - mdf * l6**2, 6.246 * e4 - mdf * l6**2))
    c = LinkParams(mc, l1 / 2, (0.0051 * e4, 0.959 * e4, 0.959 * e4))
    a = LinkParams(ma, l2 / 2, (0.001843 * e4, 0.4864 * e4, 0.4864 * e4))
    return PhantomParams("cavusoglu", 11.87 * e4, l1, -l3, l2, be, df, c, a)


PHANTOM_PARAMS: dict[str, PhantomParams] = {
    "appendix_b": APPENDIX_B,
    "cavusoglu": cavusoglu_params(),
}


class PhantomModel(PinocchioModel):
    """The PHANToM 1.5 as a ``DeviceModel`` (pinocchio on the open tree, ``q_t = S q``).

    Args:
        params: ``"appendix_b"`` (thesis Table B.1, default), ``"cavusoglu"``, or a
            ``PhantomParams``.
        gravity: False leaves G out (an observer's model for thesis section 5.2.1).
        viscous: viscous joint friction (N m s/rad), scalar or per joint, default 0.
        joint_names: names of phi1, phi2, phi3.
    """

    home = HOME

    def __init__(
        self,
        params: str | PhantomParams = "appendix_b",
        *,
        gravity: bool = True,
        viscous: float | tuple[float, float, float] = 0.0,
        joint_names: tuple[str, str, str] = ("phi1", "phi2", "phi3"),
    ) -> None:
        if isinstance(params, str):
            if params not in PHANTOM_PARAMS:
                raise ValueError(
                    f"params must be one of {', '.join(PHANTOM_PARAMS)}, got {params!r}"
                )
            params = PHANTOM_PARAMS[params]
        if not isinstance(params, PhantomParams):
            raise ValueError(f"params must be a name or PhantomParams, got {params!r}")
        self.params = params
        p = params
        joints = [
            TreeJoint("phi1", None, "z", inertia=(0.0, 0.0, p.base_inertia_kg_m2)),
            TreeJoint(
                "phi2",
                "phi1",
                "y",
                flip=True,
                mass=p.link1.mass_kg,
                com=(p.link1.com_m, 0.0, 0.0),
                inertia=p.link1.inertia_kg_m2,
            ),
            TreeJoint(
                "elbow",
                "phi2",
                "y",
                xyz=(p.l1_m, 0.0, 0.0),
                mass=p.link4.mass_kg,
                com=(-p.link4.com_m, 0.0, 0.0),
                inertia=p.link4.inertia_kg_m2,
            ),
            TreeJoint(
                "phi3",
                "phi1",
                "y",
                flip=True,
                mass=p.link2.mass_kg,
                com=(p.link2.com_m, 0.0, 0.0),
                inertia=p.link2.inertia_kg_m2,
            ),
            TreeJoint(
                "crank_hinge",
                "phi3",
                "y",
                xyz=(p.l2_m, 0.0, 0.0),
                mass=p.link3.mass_kg,
                com=(p.link3.com_m, 0.0, 0.0),
                inertia=p.link3.inertia_kg_m2,
            ),
        ]
        model, fid = tree_model(joints, "elbow", (-p.le4_m, 0.0, 0.0))
        super().__init__(
            model, fid, joint_names, np.array(TREE_MAP), gravity=gravity, viscous=viscous
        )

    def __repr__(self) -> str:
        return (
            f"PhantomModel(params={self.params.name!r}, gravity={self.gravity_enabled}, "
            f"viscous={self.viscous.tolist()})"
        )


@dataclass(frozen=True)
class PhantomSettings:
    """The PHANToM model a node builds (parameter group ``phantom.``)."""

    params: str = field(
        default="appendix_b",
        metadata=param(
            description=(
                "PHANToM 1.5 parameter set: thesis Table B.1 or Cavusoglu-Feygin-Tendick 2002"
            ),
            choices=tuple(PHANTOM_PARAMS),
        ),
    )
    gravity: bool = field(
        default=True,
        metadata=param(
            description="include gravity in the model (false: an observer that leaves G out)"
        ),
    )
    viscous_n_m_s_per_rad: float = field(
        default=0.0,
        metadata=param(description="viscous joint friction", unit="N m s/rad", bounds=(0.0, 10.0)),
    )

    def model(self) -> PhantomModel:
        """The ``PhantomModel`` with these settings."""
        return PhantomModel(
            self.params, gravity=self.gravity, viscous=float(self.viscous_n_m_s_per_rad)
        )
