"""A simulated arm's hidden truth: its URDF with the inertias, friction and armature a built arm
has and its CAD lacks.

``draw_truth`` returns the URDF text with every moving body's child link changed (its mass
scaled by a factor off by ``mass_off`` either way, its centre of mass moved by ``com_shift_m``
in a random direction, its inertia about the centre of mass scaled with the mass) and each
joint's friction and armature drawn in proportion to its effort limit (the URDF's ``<limit
effort>``, or ``default_effort``). Give it to the simulated arm (the device node's
``robot_description`` or ``urdf_path``) while the observer keeps the URDF as written: what it
misses is then what an identification must find. The draw is the seed's.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from haptic_dob.core.models import UrdfModel
from haptic_dob.core.models._pinocchio_inertia import bodies
from haptic_dob.core.models._pinocchio_urdf import read_urdf
from haptic_dob.identification.arm_urdf import (
    JointDynamics,
    LinkInertial,
    link_inertials,
    rewrite_urdf,
)


@dataclass(frozen=True)
class TruthSpread:
    """How far the truth is from the URDF: mass factor off by ``mass_off`` (a range, either
    way), COM shift (m, a range), and per N m of effort limit the Coulomb friction (N m), the
    viscous friction (N m s/rad) and the armature (kg m^2), each a range."""

    mass_off: tuple[float, float] = (0.10, 0.20)
    com_shift_m: tuple[float, float] = (0.01, 0.02)
    coulomb_per_n_m: tuple[float, float] = (0.004, 0.008)
    viscous_per_n_m: tuple[float, float] = (0.002, 0.004)
    armature_per_n_m: tuple[float, float] = (3e-4, 1e-3)
    default_effort_n_m: float = 50.0


def draw_truth(urdf: str, tip_frame: str, seed: int, spread: TruthSpread | None = None) -> str:
    """The URDF text of a hidden truth for the arm's chain to ``tip_frame`` (see the module)."""
    s = spread or TruthSpread()
    rng = np.random.default_rng(seed)
    xml = read_urdf(urdf)
    model = UrdfModel(xml, tip_frame)
    cad = link_inertials(xml)
    links = {}
    for body in bodies(model):
        name = body.links[0][0]
        li = cad[name]
        factor = 1.0 + rng.choice((-1.0, 1.0)) * rng.uniform(*s.mass_off)
        direction = rng.normal(size=3)
        shift = direction / np.linalg.norm(direction) * rng.uniform(*s.com_shift_m)
        links[name] = LinkInertial(li.mass * factor, li.com + shift, li.inertia * factor)
    dynamics = {}
    for name, limit in zip(model.joint_names, model.effort_limits, strict=True):
        effort = limit if limit > 0.0 else s.default_effort_n_m
        dynamics[name] = JointDynamics(
            damping=effort * rng.uniform(*s.viscous_per_n_m),
            friction=effort * rng.uniform(*s.coulomb_per_n_m),
            armature=effort * rng.uniform(*s.armature_per_n_m),
        )
    note = (
        f"a simulated arm's hidden truth, drawn by haptic_sim.arm.truth.draw_truth (seed {seed}): "
        "link masses, centres of mass, joint friction and armature differ from the URDF"
    )
    return rewrite_urdf(xml, links, dynamics, note)
