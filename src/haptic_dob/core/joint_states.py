"""A model's joint vectors out of a ``sensor_msgs/JointState``, as a driver publishes it.

Joints are matched by name (any order, extra joints ignored; a message without names must hold
the model's joints in model order); a message without velocities is differentiated from the
previous positions; a message without efforts reads as zero effort. Anything unusable raises
``ValueError`` naming what is wrong, so a node can refuse the one message and go on.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import Any, NamedTuple

import numpy as np


class JointMap:
    """Pick a model's joints out of a JointState by name (any order, extra joints ignored)."""

    def __init__(self, joint_names: Sequence[str]) -> None:
        self.joint_names = tuple(joint_names)
        self._names: tuple[str, ...] | None = None
        self._index: list[int] = []

    def index(self, names: Sequence[str], n_values: int) -> list[int]:
        """Positions of the model's joints in a message with ``names`` (ValueError if missing)."""
        if not names:
            if n_values != len(self.joint_names):
                raise ValueError(
                    f"joint_states without names must have {len(self.joint_names)} values in "
                    f"model order, got {n_values}"
                )
            return list(range(n_values))
        if names == self._names:  # the same names as the last message (tuples)
            return self._index
        where = {n: i for i, n in enumerate(names)}
        missing = [j for j in self.joint_names if j not in where]
        if missing:
            raise ValueError(
                f"joint_states lacks joint(s) {', '.join(missing)} of the model "
                f"(it has: {', '.join(names)})"
            )
        self._names = tuple(names)
        self._index = [where[j] for j in self.joint_names]
        return self._index


def pick(values: Any, index: list[int], what: str, n_names: int) -> list[float]:
    """The model's joints (floats) out of one JointState field (ValueError on a length mismatch)."""
    if len(values) != n_names:
        raise ValueError(f"joint_states {what} has {len(values)} values for {n_names} joints")
    seq = values.tolist() if isinstance(values, np.ndarray) else values
    return [float(seq[i]) for i in index]


class JointVectors(NamedTuple):
    """One sample's model-order joint positions (rad or m), velocities and efforts (N m or N)."""

    q: list[float]
    qd: list[float]
    tau: list[float]


def joint_vectors(
    joints: JointMap,
    names: Sequence[str],
    position: Any,
    velocity: Any,
    effort: Any,
    previous_q: list[float] | None,
    dt_s: float,
) -> JointVectors:
    """The model's q, q', tau from one JointState's fields.

    Without velocities, q' is the backward difference from ``previous_q`` over ``dt_s`` (s), or
    zero when there is none; without efforts, tau is zero. ``ValueError`` for a missing joint, a
    field of the wrong length, or NaN/inf.
    """
    idx = joints.index(names, len(position))
    n = len(names) or len(position)
    q = pick(position, idx, "position", n)
    if len(velocity):
        qd = pick(velocity, idx, "velocity", n)
    elif previous_q is not None and dt_s > 0.0:
        qd = [(a - b) / dt_s for a, b in zip(q, previous_q, strict=True)]
    else:
        qd = [0.0] * len(q)
    tau = pick(effort, idx, "effort", n) if len(effort) else [0.0] * len(q)
    if not all(map(math.isfinite, q + qd + tau)):
        raise ValueError("joint_states holds NaN or inf")
    return JointVectors(q, qd, tau)
