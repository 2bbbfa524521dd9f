"""The teleoperation loop's stability against the channel's delay: the protocol and the sweep.

Protocol: the hand pushes the master forward and holds (``push_hold``: the slave presses on the
table), through a light grip (``grip_n_per_m``, ``grip_n_s_per_m``: little damping from the hand,
the harder case); a force pulse on the master at ``pulse_at_s`` excites the loop. A stable loop
settles; an unstable one grows into a limit cycle (the slave bouncing on the table, the master
shaking). A delay is *stable* when the master's oscillation over the last second
(``haptic_sim.teleop.result.oscillation``: standard deviation above 2 Hz) stays below
``threshold_mm``; the channel's lowest net energy is reported beside it (a loop that vibrates
draws energy from the channel: it is active).
"""

from __future__ import annotations

from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass

from haptic_dob.core.validation import nonnegative, positive
from haptic_msgs_py.stamps import period_ns
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.session import run_teleop


@dataclass(frozen=True)
class DelayProtocol:
    """The push-hold-pulse protocol of a stability point (see the module docstring)."""

    push_m: float = 0.012
    grip_n_per_m: float = 150.0
    grip_n_s_per_m: float = 3.0
    pulse_n: float = 1.0
    pulse_at_s: float = 2.0
    pulse_s: float = 0.02
    duration_s: float = 4.0
    threshold_mm: float = 0.1

    def __post_init__(self) -> None:
        positive("push_m", self.push_m)
        positive("grip_n_per_m", self.grip_n_per_m)
        nonnegative("grip_n_s_per_m", self.grip_n_s_per_m)
        positive("pulse_s", self.pulse_s)
        positive("threshold_mm", self.threshold_mm)
        if not self.pulse_at_s + self.pulse_s + 1.0 <= self.duration_s:
            raise ValueError("the protocol needs at least 1 s after the pulse")

    def config(self, base: TeleopConfig, delay_ms: float, passivity: bool) -> TeleopConfig:
        """``base`` with this protocol's hand and length, the delay and the passivity control."""
        return base.override(
            {
                "/**/channel_node": {
                    "channel.round_trip_delay_ms": float(delay_ms),
                    "channel.passivity": bool(passivity),
                },
                "/**/device_node": {"duration_s": self.duration_s},
                "/master/device_node": {
                    "hand.behaviour": "push_hold",
                    "hand.offset_m": self.push_m,
                    "hand.stiffness_n_per_m": self.grip_n_per_m,
                    "hand.damping_n_s_per_m": self.grip_n_s_per_m,
                    "hand.perturbation_n": self.pulse_n,
                    "hand.perturbation_at_s": self.pulse_at_s,
                    "hand.perturbation_s": self.pulse_s,
                },
            }
        )


@dataclass(frozen=True)
class DelayPoint:
    """The loop at one delay, with or without passivity control."""

    round_trip_delay_ms: float  # as simulated: whole samples each way
    passivity: bool
    oscillation_mm: float
    channel_energy_min_j: float
    dissipated_j: float
    contact_force_rms_n: float
    stable: bool


def delay_point(
    protocol: DelayProtocol, base: TeleopConfig, delay_ms: float, passivity: bool
) -> DelayPoint:
    """Run the protocol at one delay."""
    config = protocol.config(base, delay_ms, passivity)
    m = run_teleop(config).metrics()
    return DelayPoint(
        config.channel.simulated_round_trip_ms(period_ns(config.loop.rate_hz)),
        bool(passivity),
        m.oscillation_mm,
        m.channel_energy_min_j,
        m.dissipated_j,
        m.contact_force_rms_n,
        bool(m.oscillation_mm < protocol.threshold_mm),
    )


def delay_sweep(
    base: TeleopConfig,
    delays_ms: list[float],
    protocol: DelayProtocol | None = None,
    passivity: tuple[bool, ...] = (False, True),
    workers: int = 1,
) -> list[DelayPoint]:
    """Every delay (ms) with and without passivity control (in parallel with ``workers``)."""
    protocol = protocol or DelayProtocol()
    if not delays_ms:
        raise ValueError("delays must not be empty")
    for d in delays_ms:
        nonnegative("delay_ms", d)
    cases = [(d, p) for p in passivity for d in delays_ms]
    n = len(cases)
    delays, flags = [d for d, _ in cases], [p for _, p in cases]
    if workers > 1:
        with ProcessPoolExecutor(workers) as ex:
            return list(ex.map(delay_point, [protocol] * n, [base] * n, delays, flags))
    return [delay_point(protocol, base, d, p) for d, p in cases]


def boundary_ms(points: list[DelayPoint], passivity: bool) -> float | None:
    """The shortest delay (ms) that is not stable (None: every delay is)."""
    bad = [p.round_trip_delay_ms for p in points if p.passivity == passivity and not p.stable]
    return min(bad) if bad else None
