"""Sensor models: a 6-axis force sensor at the handle (force part) and an incremental encoder."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from haptic_dob.core.validation import finite_scalar, nonnegative, positive
from haptic_dob.runtime.params import param

#: ATI Nano-17-class defaults: ~1/320 N resolution, a few mN of noise, filtered to 500 Hz
NANO17_NOISE_STD_N = 0.005
NANO17_BANDWIDTH_HZ = 500.0


@dataclass(frozen=True)
class ForceSensorParams:
    """Force sensor: white noise (N, std), first-order bandwidth (Hz), constant bias (N)."""

    noise_std_n: float = field(
        default=NANO17_NOISE_STD_N,
        metadata=param(description="force-sensor white noise (std)", unit="N", bounds=(0.0, 10.0)),
    )
    bandwidth_hz: float = field(
        default=NANO17_BANDWIDTH_HZ,
        metadata=param(
            description="force-sensor first-order bandwidth", unit="Hz", bounds=(1.0, 1e5)
        ),
    )
    bias_n: float = field(
        default=0.0, metadata=param(description="force-sensor bias", unit="N", bounds=(-10.0, 10.0))
    )

    def __post_init__(self) -> None:
        nonnegative("noise_std_n", self.noise_std_n)
        positive("bandwidth_hz", self.bandwidth_hz)
        finite_scalar("bias_n", self.bias_n)


class ForceSensor:
    """First-order low-pass at the physics rate, then bias and noise added at each read.

    Args:
        params: sensor settings.
        dt_physics: physics step (s) at which ``track`` is called.
        rng: generator for the noise (seeded by the caller).
    """

    def __init__(self, params: ForceSensorParams, dt_physics: float, rng: np.random.Generator):
        self.params = params
        self.alpha = 1.0 - math.exp(-2.0 * math.pi * params.bandwidth_hz * dt_physics)
        self._rng = rng
        self.state = 0.0
        self._noise = np.zeros(0)
        self._i = 0

    def track(self, force: float) -> None:
        """Advance the filter one physics step with the true force (N)."""
        self.state += self.alpha * (force - self.state)

    def read(self) -> float:
        """The measured force (N) now: filtered + bias + noise."""
        if self._i >= self._noise.size:
            self._noise = self._rng.standard_normal(4096) * self.params.noise_std_n
            self._i = 0
        value = self.state + self.params.bias_n + float(self._noise[self._i])
        self._i += 1
        return value


def quantize(x: float, resolution: float) -> float:
    """Encoder reading of position ``x`` (m) with ``resolution`` (m): nearest count."""
    return round(x / resolution) * resolution
