"""Excitation trajectories for an arm's identification: finite Fourier series, from its URDF.

Each joint moves as ``q(t) = q_0 + sum_l a_l / (w l) sin(w l t) + b_l / (w l) (1 - cos(w l t))``,
``l = 1..L``, ``w = 2 pi / period``: periodic, at ``q_0`` at rest at t = 0 and at every period's
end (``sum a_l = 0``, ``sum l b_l = 0``: ``a_1`` and ``b_1`` follow from the others). The design
(``design_excitation``) minimises the log of the condition number of the base regressor
(``arm_parameters``: columns scaled to unit norm, Coulomb term the velocity's sign) over
``samples`` points of a period, within each joint's position limits (less a margin), speed and
acceleration limits, the effort the CAD model needs (a share of the URDF's limits) and a
workspace box for the tip: the best of ``candidates`` random series scaled to the limits, then
scipy's SLSQP (position, speed and acceleration are linear in the coefficients). The result is
checked on a ten times finer grid and scaled down until it holds there.
``FourierExcitation`` is the trajectory file (YAML) the slave controller plays.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from numpy.typing import NDArray

Arr = NDArray[np.float64]


@dataclass(frozen=True)
class FourierExcitation:
    """A periodic joint trajectory (see the module): joints, period (s), start ``q_0`` (rad or
    m) and per joint the coefficients ``a_l``, ``b_l`` (rad/s or m/s), l = 1..L."""

    joints: tuple[str, ...]
    period_s: float
    start: tuple[float, ...]
    sine: tuple[tuple[float, ...], ...]
    cosine: tuple[tuple[float, ...], ...]

    def motion(self, t: Arr) -> tuple[Arr, Arr, Arr]:
        """Positions, velocities and accelerations (len(t), dof) at times ``t`` (s)."""
        a, b = np.array(self.sine), np.array(self.cosine)
        w = 2.0 * math.pi / self.period_s * np.arange(1, a.shape[1] + 1)
        s, c = np.sin(np.outer(t, w)), np.cos(np.outer(t, w))
        q = np.array(self.start) + (s / w) @ a.T + ((1.0 - c) / w) @ b.T
        return q, c @ a.T + s @ b.T, (-s * w) @ a.T + (c * w) @ b.T

    def save(self, path: str | Path, note: str = "") -> None:
        """Write the trajectory file (YAML), ``note`` as a comment at its top."""
        doc = {
            "kind": "fourier",
            "joints": list(self.joints),
            "period_s": self.period_s,
            "start": list(self.start),
            "sine": [list(r) for r in self.sine],
            "cosine": [list(r) for r in self.cosine],
        }
        head = "# an arm's excitation (haptic_dob.identification.arm_excitation)\n"
        head += "".join(f"# {line}\n" for line in note.splitlines())
        Path(path).write_text(head + yaml.safe_dump(doc, sort_keys=False), encoding="utf-8")

    @classmethod
    def load(cls, path: str | Path) -> FourierExcitation:
        """Read a trajectory file; ``ValueError`` with one line when it is not one."""
        try:
            doc: Any = yaml.safe_load(Path(path).read_text(encoding="utf-8"))
            out = cls(
                tuple(str(j) for j in doc["joints"]),
                float(doc["period_s"]),
                tuple(float(v) for v in doc["start"]),
                tuple(tuple(float(v) for v in r) for r in doc["sine"]),
                tuple(tuple(float(v) for v in r) for r in doc["cosine"]),
            )
        except (OSError, yaml.YAMLError, KeyError, TypeError, ValueError) as exc:
            raise ValueError(f"{path}: not an excitation trajectory file ({exc})") from None
        dof = len(out.joints)
        shapes = {len(out.start), len(out.sine), len(out.cosine)}
        widths = {len(r) for r in (*out.sine, *out.cosine)}
        if shapes != {dof} or len(widths) != 1 or not out.period_s > 0.0:
            raise ValueError(f"{path}: the excitation's coefficients do not match its joints")
        return out


@dataclass(frozen=True)
class ExcitationLimits:
    """What the excitation stays within: joint position limits less ``margin_rad``, a share of
    each joint's speed limit (at most ``max_speed_rad_s``), ``max_accel_rad_s2``, a share of
    the effort limits, and a box for the tip (base frame, m; None: anywhere)."""

    margin_rad: float = 0.1
    speed_share: float = 0.5
    max_speed_rad_s: float = 1.5
    max_accel_rad_s2: float = 6.0
    effort_share: float = 0.8
    box_lo: tuple[float, float, float] | None = None
    box_hi: tuple[float, float, float] | None = None


@dataclass(frozen=True)
class ExcitationDesign:
    """The designed excitation and its figures: condition numbers (the best random start's and
    the design's), peak speed, acceleration and effort (as shares of their limits)."""

    excitation: FourierExcitation
    condition_number: float
    start_condition_number: float
    peak_speed_share: float
    peak_accel_share: float
    peak_effort_share: float
    tip_lo: tuple[float, float, float] = field(default=(0.0, 0.0, 0.0))
    tip_hi: tuple[float, float, float] = field(default=(0.0, 0.0, 0.0))
