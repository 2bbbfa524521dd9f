"""The simulated hand in 3-D: a push along a direction, motions across it, and their sum per axis.

The hand's reference in space is ``x_r(t) = p0 + u r(t) + e1 r1(t) + e2 r2(t)``: ``p0`` where the
end effector starts, ``u`` the push direction, ``r(t)`` the 1-D reference of ``haptic_sim.hand``
(push-and-hold or semi-random, with its ramp and force pulse along ``u``) and ``r1``, ``r2``
semi-random motions across ``u`` (``lateral_amplitude_m``; none when 0). ``hand_references``
builds the 1-D references with their directions (the simulated arm sums them itself);
``CartesianReference`` sums them block by block and gives each axis of a Cartesian device its
component (``axis(i)``: what a 1-D plant asks its reference for).
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
from numpy.typing import NDArray

from haptic_sim.hand import Block, HandParams, HandReference

Vec = NDArray[np.float64]


def perpendiculars(u: Vec) -> tuple[Vec, Vec]:
    """Two unit vectors completing ``u`` to a right-handed orthonormal basis."""
    a = np.array([1.0, 0.0, 0.0]) if abs(u[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(u, a)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(u, e1)


def hand_references(
    hand: HandParams,
    direction: Vec,
    lateral_amplitude_m: float,
    dt: float,
    rngs: list[np.random.Generator],
) -> list[tuple[HandReference, Vec]]:
    """The 1-D references of an active hand and their unit directions: the push along
    ``direction`` (``rngs[0]``), then two semi-random motions across it (``rngs[1]``, ``rngs[2]``)
    when ``lateral_amplitude_m`` > 0; none for ``behaviour: none``. ``dt``: the physics step (s)."""
    if not hand.active:
        return []
    refs = [(HandReference(hand, dt, rngs[0]), direction)]
    if lateral_amplitude_m > 0.0:
        lateral = replace(
            hand,
            behaviour="semi_random",
            offset_m=0.0,
            amplitude_m=lateral_amplitude_m,
            perturbation_n=0.0,
        )
        for rng, e in zip(rngs[1:3], perpendiculars(direction), strict=True):
            refs.append((HandReference(lateral, dt, rng), e))
    return refs


class CartesianReference:
    """``p0 + sum_j r_j(t) e_j`` per block: position, velocity and feed-forward force, (n, 3).

    Args:
        refs: the 1-D references and their unit directions (``hand_references``).
        origin: ``p0``, where the end effector starts (m).
    """

    def __init__(self, refs: list[tuple[HandReference, Vec]], origin: Vec) -> None:
        if not refs:
            raise ValueError("a Cartesian hand reference needs at least one 1-D reference")
        self._refs = refs
        self._origin = np.asarray(origin, dtype=np.float64)
        self._start, self._end = 0, 0  # the summed block's samples [start, end)
        self._block: Block = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros((0, 3)))

    def arrays(self, i: int) -> tuple[Block, int]:
        """The summed block holding sample ``i`` and its index there (samples go in order)."""
        if not self._start <= i < self._end:
            parts = [(ref.arrays(i), e) for ref, e in self._refs]
            (_, _, _, j), _ = parts[0]
            pos = self._origin + sum(np.outer(p[0], e) for p, e in parts)
            vel = sum(np.outer(p[1], e) for p, e in parts)
            ff = sum(np.outer(p[2], e) for p, e in parts)
            self._block = (np.asarray(pos), np.asarray(vel), np.asarray(ff))
            self._start, self._end = i - j, i - j + len(pos)
        return self._block, i - self._start

    def prepare(self, i: int) -> None:
        """Generate the 1-D references' next blocks ahead (``HandReference.prepare``)."""
        for ref, _ in self._refs:
            ref.prepare(i)

    def axis(self, index: int) -> AxisReference:
        """Axis ``index``'s component (0, 1, 2: x, y, z), as a 1-D reference."""
        return AxisReference(self, index)


class AxisReference:
    """One axis of a ``CartesianReference``, with ``HandReference``'s ``arrays`` and ``prepare``."""

    __slots__ = ("_index", "_space")

    def __init__(self, space: CartesianReference, index: int) -> None:
        self._space, self._index = space, index

    def arrays(self, i: int) -> tuple[Vec, Vec, Vec, int]:
        """(position, velocity, feed-forward force) of this axis holding sample ``i``, its index."""
        (pos, vel, ff), j = self._space.arrays(i)
        c = self._index
        return pos[:, c], vel[:, c], ff[:, c], j

    def prepare(self, i: int) -> None:
        """Generate ahead what sample ``i`` will need."""
        self._space.prepare(i)
