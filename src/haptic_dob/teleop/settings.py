"""What a teleoperation session is set with: the architecture and mapping (``TeleopSettings``)
and the channel between master and slave (``ChannelSettings``).

Frames and units: the slave's base frame carries the channel's quantities. The master's
displacement ``d_m`` from its start point maps to the slave's as ``position_scale * R d_m``; a
force ``F`` of the slave's side reaches the master as ``force_scale * R^T F``; ``R`` is a
rotation (row-major 3x3 ``rotation``); for a 1-DOF master (the slide) only its axis's column
matters and the rendered force is taken along the axis. Architectures: ``position_force``, the
slave tracks the master's (delayed) position and the master renders the slave's contact force,
from the slave's observer (``force_source: estimate``) or a wrist sensor (``sensor``);
``position_position``, both track each other's delayed position and the master renders a
coupling spring-damper ``K (x_s - x_m) + B (v_s - v_m)`` (slave units).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.runtime.params import param

ARCHITECTURES = ("position_force", "position_position")
FORCE_SOURCES = ("estimate", "sensor")
IDENTITY = (1.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0)


@dataclass(frozen=True)
class TeleopSettings:
    """Architecture, master-to-slave mapping and the master's coupling (group ``teleop.``)."""

    architecture: str = field(
        default="position_force",
        metadata=param(
            description="what the master renders", choices=ARCHITECTURES, read_only=True
        ),
    )
    force_source: str = field(
        default="estimate",
        metadata=param(
            description=(
                "position_force: the slave force sent back (observer's or wrist sensor's)"
            ),
            choices=FORCE_SOURCES,
            details=("estimate: the observer's estimate; sensor: the wrist sensor's reading."),
        ),
    )
    rotation: tuple[float, ...] = field(
        default=IDENTITY,
        metadata=param(
            description="rotation from the master's frame to the slave's (row-major 3x3)"
        ),
    )
    position_scale: float = field(
        default=1.0,
        metadata=param(
            description="slave displacement per master displacement", bounds=(1e-3, 1e3)
        ),
    )
    force_scale: float = field(
        default=1.0, metadata=param(description="master force per slave force", bounds=(0.0, 1e3))
    )
    master_max_force_n: float = field(
        default=4.0,
        metadata=param(
            description=("the largest force the master renders (its controller's max_force_n)"),
            unit="N",
            bounds=(1e-3, 1e4),
            details=("In master units: the channel books no more than the master renders."),
        ),
    )
    coupling_n_per_m: float = field(
        default=1000.0,
        metadata=param(
            description="position_position: the master's coupling stiffness (slave units)",
            unit="N/m",
            bounds=(0.0, 1e6),
        ),
    )
    coupling_n_s_per_m: float = field(
        default=20.0,
        metadata=param(
            description="position_position: the master's coupling damping (slave units)",
            unit="N s/m",
            bounds=(0.0, 1e4),
        ),
    )

    def __post_init__(self) -> None:
        if self.architecture not in ARCHITECTURES:
            raise ValueError(
                f"architecture must be one of {', '.join(ARCHITECTURES)}, got {self.architecture!r}"
            )
        if self.force_source not in FORCE_SOURCES:
            raise ValueError(
                f"force_source must be one of {', '.join(FORCE_SOURCES)}, got {self.force_source!r}"
            )
        r = np.asarray(self.rotation, dtype=np.float64)
        if r.shape != (9,) or not np.all(np.isfinite(r)):
            raise ValueError(f"rotation must be 9 finite numbers (row-major 3x3), got {r.tolist()}")
        m = r.reshape(3, 3)
        if not np.allclose(m @ m.T, np.eye(3), atol=1e-6) or np.linalg.det(m) < 0.0:
            raise ValueError(f"rotation must be a rotation matrix (R R^T = I, det 1), got {r}")
        object.__setattr__(self, "rotation", tuple(float(x) for x in r))
        positive("position_scale", self.position_scale)
        nonnegative("force_scale", self.force_scale)
        positive("master_max_force_n", self.master_max_force_n)
        nonnegative("coupling_n_per_m", self.coupling_n_per_m)
        nonnegative("coupling_n_s_per_m", self.coupling_n_s_per_m)

    @property
    def matrix(self) -> np.ndarray:
        """``R`` (3, 3)."""
        return np.asarray(self.rotation).reshape(3, 3)


@dataclass(frozen=True)
class ChannelSettings:
    """The communication channel between master and slave (group ``channel.``).

    Delays are whole samples: each direction delays by half the round trip, at least one sample
    (the loop's own transport), plus a jitter drawn per message from ``[0, jitter_ms]``. A lost
    message never arrives; the receiver keeps the newest message that did. ``timeout_s``: a
    side whose peer sent nothing that arrived for that long (in samples) stops using it (the
    master renders zero force, the slave holds where it is). ``passivity``: the time-domain
    passivity controller on both ports (off: the observers still book the energy).
    """

    round_trip_delay_ms: float = field(
        default=2.0,
        metadata=param(
            description="round-trip delay; each way half of it, at least one sample",
            unit="ms",
            bounds=(0.0, 1e4),
            read_only=True,
        ),
    )
    jitter_ms: float = field(
        default=0.0,
        metadata=param(
            description="largest extra one-way delay, uniform per message",
            unit="ms",
            bounds=(0.0, 1e3),
            read_only=True,
        ),
    )
    loss: float = field(
        default=0.0,
        metadata=param(
            description="probability that a message is lost", bounds=(0.0, 0.99), read_only=True
        ),
    )
    seed: int = field(
        default=0,
        metadata=param(
            description="seed of jitter and loss", bounds=(0, 2**31 - 1), read_only=True
        ),
    )
    cut_at_s: float = field(
        default=0.0,
        metadata=param(
            description="the link dies at this sample time, both ways (0: never)",
            unit="s",
            bounds=(0.0, 1e7),
            read_only=True,
        ),
    )
    timeout_s: float = field(
        default=0.02,
        metadata=param(
            description="a peer silent this long (sample time) counts as lost",
            unit="s",
            bounds=(1e-3, 10.0),
        ),
    )
    passivity: bool = field(
        default=False, metadata=param(description="time-domain passivity control on both ports")
    )

    def __post_init__(self) -> None:
        nonnegative("round_trip_delay_ms", self.round_trip_delay_ms)
        nonnegative("jitter_ms", self.jitter_ms)
        if not 0.0 <= self.loss < 1.0:
            raise ValueError(f"loss must be in [0, 1), got {self.loss!r}")
        nonnegative("cut_at_s", self.cut_at_s)
        positive("timeout_s", self.timeout_s)
        if self.timeout_s * 1e3 <= self.jitter_ms:
            raise ValueError(
                f"timeout_s ({self.timeout_s:g} s) must exceed the jitter ({self.jitter_ms:g} ms): "
                "messages bunch by up to the jitter"
            )

    def delay_samples(self, period_ns: int) -> int:
        """One-way delay (samples): half the round trip, rounded half up, at least 1."""
        return max(1, math.floor(self.round_trip_delay_ms * 1e6 / 2.0 / period_ns + 0.5))

    def simulated_round_trip_ms(self, period_ns: int) -> float:
        """The round trip the channel gives (ms): twice the one-way delay in whole samples."""
        return 2.0 * self.delay_samples(period_ns) * period_ns * 1e-6

    def jitter_samples(self, period_ns: int) -> int:
        """The largest extra one-way delay (samples)."""
        return round(self.jitter_ms * 1e6 / period_ns)

    def cut_sample(self, period_ns: int) -> int | None:
        """The first sample whose messages are lost (None: never)."""
        return None if self.cut_at_s <= 0.0 else math.ceil(self.cut_at_s * 1e9 / period_ns)
