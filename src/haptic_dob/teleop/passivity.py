"""Time-domain passivity of one port of a delayed channel (Hannaford & Ryu 2002; for delay, the
time-delay power network of Ryu, Artigas & Preusche 2010).

Each end books the energy at its own port every sample, split by the sign of the power ``y`` the
channel delivers there: ``E_out += y T`` while ``y > 0``, ``E_in -= y T`` while ``y < 0``; its
``E_in`` travels to the other end with the messages. Passive: ``E_out(k) <= E_in,remote(k -
delay)``, checked against the newest ``E_in,remote`` received. The controller enforces it each
sample: at the master's end (velocity in, force out) a damper ``F - alpha v``, at the slave's
(force in, velocity out) ``v + beta F``, each just enough that the sample's output energy meets
the bound, and never more than the original force (or velocity) along the other variable. A
sample's power is booked with the sample's output and input. Values are 3-vectors of floats
(slave units: N, m/s); nothing here allocates arrays. Why: docs/design/teleoperation.md.
"""

from __future__ import annotations

from haptic_dob.core.control import Force


class PassivityPort:
    """The energy book and passivity controller of one end of the channel.

    Args:
        dt: sample period (s).
        enabled: whether the controller acts (the observer books the energy either way).
    """

    __slots__ = ("dissipated_j", "dt", "e_in", "e_out", "enabled", "remote_in")

    def __init__(self, dt: float, enabled: bool) -> None:
        self.dt = dt
        self.enabled = enabled
        self.e_in = 0.0  # J that came into the channel here
        self.e_out = 0.0  # J the channel gave out here
        self.remote_in = 0.0  # the other end's E_in, newest received (J)
        self.dissipated_j = 0.0  # J the controller took out

    def received(self, remote_in: float) -> None:
        """The other end's ``E_in`` (J) arrived (sums only grow: the largest is the newest)."""
        if remote_in > self.remote_in:
            self.remote_in = remote_in

    @property
    def observed_j(self) -> float:
        """The passivity observer: ``E_in,remote - E_out`` (J), >= 0 while passive."""
        return self.remote_in - self.e_out

    def _excess(self, y: float) -> float:
        """Energy beyond the bound if this sample delivers power ``y`` (W); <= 0 when allowed."""
        return self.e_out + y * self.dt - self.remote_in if self.enabled and y > 0.0 else 0.0

    def _book(self, y: float) -> None:
        if y > 0.0:
            self.e_out += y * self.dt
        else:
            self.e_in -= y * self.dt

    def impedance(self, force: Force, velocity: Force) -> Force:
        """Master's end: the force to render for ``velocity`` (the channel delivers ``F . v``)."""
        f0, f1, f2 = force
        v0, v1, v2 = velocity
        y = f0 * v0 + f1 * v1 + f2 * v2
        excess = self._excess(y)
        if excess > 0.0:
            alpha = excess / (self.dt * (v0 * v0 + v1 * v1 + v2 * v2))
            f0, f1, f2 = f0 - alpha * v0, f1 - alpha * v1, f2 - alpha * v2
            self.dissipated_j += excess
            y = f0 * v0 + f1 * v1 + f2 * v2
        self._book(y)
        return (f0, f1, f2)

    def admittance(self, velocity: Force, force: Force) -> Force:
        """Slave's end: the velocity to command against the slave's ``force`` (the environment's
        force on the slave; the channel delivers ``-F . v``)."""
        f0, f1, f2 = force
        v0, v1, v2 = velocity
        y = -(f0 * v0 + f1 * v1 + f2 * v2)
        excess = self._excess(y)
        if excess > 0.0:
            beta = excess / (self.dt * (f0 * f0 + f1 * f1 + f2 * f2))
            v0, v1, v2 = v0 + beta * f0, v1 + beta * f1, v2 + beta * f2
            self.dissipated_j += excess
            y = -(f0 * v0 + f1 * v1 + f2 * v2)
        self._book(y)
        return (v0, v1, v2)
