"""The control cycle, written once: sample k -> wall force, estimate -> command k.

Batch runs and the node graph run the same three stages in the same order, so a lockstep graph
reproduces a batch run bit for bit:

1. ``wall_force``: the virtual environment's force from the end-effector pose and twist of
   sample k, plus a known excitation at the sample's time (environment node);
2. ``estimate``: the observer updated with sample k (positions, velocities, the effort applied
   over [k-1, k)) and its wrench at the end effector (observer node);
3. ``CommandJoin`` (``haptic_dob.core.command_join``): command k from the stamp-k inputs the law's
   mode needs (controller node), held by the device over [k, k+1).

``LoopCycle`` chains the stages for an in-process run.
"""

from __future__ import annotations

from collections.abc import Sequence
from typing import NamedTuple

from haptic_dob.core.command_join import CommandJoin
from haptic_dob.core.control import Force, ImpedanceController
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.observers.disturbance import DisturbanceObserver


def wall_force(
    wall: VirtualWall,
    position: Sequence[float],
    velocity: Sequence[float],
    excitation: Excitation | None = None,
    stamp_ns: int = 0,
) -> Force:
    """Stage 1: the wall's force on the hand (N) at the sample's end-effector point and twist,
    plus ``excitation`` at the sample's time (along the wall normal or per axis, and its holding
    spring)."""
    f = wall.force(position, velocity)  # type: ignore[arg-type]  # 3-sequences of floats
    if excitation is None:
        return f
    e = excitation.force(stamp_ns * 1e-9, wall.normal, position)
    return (f[0] + e[0], f[1] + e[1], f[2] + e[2])


def estimate(
    observer: DisturbanceObserver,
    q: Sequence[float],
    qd: Sequence[float],
    effort: Sequence[float],
) -> Force:
    """Stage 2: update the observer with sample k and return its end-effector wrench (N)."""
    observer.update(q, qd, effort)
    fe = observer.wrench(q)
    return (float(fe[0]), float(fe[1]), float(fe[2]))


class CycleResult(NamedTuple):
    """What one cycle computed from sample k: wall force, estimate (N) and command k."""

    wall_force: Force
    estimated_force: Force
    command: list[float]


class LoopCycle:
    """The three stages chained in-process (batch runs): one ``step`` per sample.

    Args:
        wall: the virtual environment.
        observer: the disturbance observer on the assumed model.
        controller: the law mapped to joints through the assumed model.
        period_ns: the sample period (ns).
        excitation: a known force the environment adds (identification), None: none.
    """

    def __init__(
        self,
        wall: VirtualWall,
        observer: DisturbanceObserver,
        controller: ImpedanceController,
        period_ns: int,
        excitation: Excitation | None = None,
    ) -> None:
        self.wall = wall
        self.excitation = excitation if excitation is not None and excitation.active else None
        self.observer = observer
        self.join = CommandJoin(controller, period_ns, not controller.model.constant_jacobian)

    def step(
        self,
        stamp_ns: int,
        q: Sequence[float],
        qd: Sequence[float],
        effort: Sequence[float],
        ee_position: Sequence[float],
        ee_velocity: Sequence[float],
        wrench_measured: Force,
        estimate_override: Force | None = None,
    ) -> CycleResult:
        """Sample k (stamp, joints, applied effort, end-effector point and twist, sensor force)
        -> the cycle's forces and command k. ``estimate_override`` replaces the observer's wrench
        at the law's input (the observer still updates)."""
        f_wall = wall_force(self.wall, ee_position, ee_velocity, self.excitation, stamp_ns)
        f_est = estimate(self.observer, q, qd, effort)
        command = self.command(stamp_ns, q, f_wall, wrench_measured, estimate_override or f_est)
        return CycleResult(f_wall, f_est, command)

    def command(
        self,
        stamp_ns: int,
        q: Sequence[float],
        f_wall: Force,
        f_measured: Force,
        f_estimated: Force,
    ) -> list[float]:
        """Stage 3 with every input of the cycle at hand (as the controller node gets them)."""
        join = self.join
        join.measured(stamp_ns, f_measured)
        join.estimated(stamp_ns, f_estimated)
        if join.needs_q:
            join.joints(stamp_ns, q)
        command = join.wall(stamp_ns, f_wall)
        if command is None:  # every input is there: only a stale stamp gives none
            raise ValueError(f"stamp {stamp_ns} ns is older than the last cycle's")
        return command
