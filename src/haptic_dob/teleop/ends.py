"""The two ends of the teleoperation channel: what the master's side and the slave's side compute
each cycle from their own sample and the newest message of the other side.

``MasterEnd.cycle``: the master's point and velocity of sample k -> the force the master renders
(its controller's wall force ``F_w``) and the message to the slave. ``SlaveEnd.cycle``: the
slave's point, velocity and contact force (estimated or measured) of sample k -> the point the
slave tracks and the message to the master. Messages (``PortMessage``) carry slave units (base
frame, m, m/s, N) and the energy that came in at the sender's port; each end puts the other's
through its ``DelayLine`` (``receive``), so only earlier samples' messages are used and the ends
may run in any order. Each end books its port's energy (master: its velocity and the force it
renders; slave: the tracked point's velocity and the contact force) and, with
``channel.passivity``, enforces it (refused under ``position_position``). A peer silent for
``timeout_s``: the master renders zero, the slave holds its point; then the slave goes on from
there and the master's force ramps back over ``timeout_s``. docs/design/teleoperation.md.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

from haptic_dob.core.control import ZERO_FORCE, Force, limit_norm
from haptic_dob.teleop.delay import DelayLine, SampleClock, _quiet
from haptic_dob.teleop.passivity import PassivityPort
from haptic_dob.teleop.settings import ChannelSettings, TeleopSettings

Vec3 = tuple[float, float, float]


class PortMessage(NamedTuple):
    """One side's port at sample ``stamp_ns`` (slave units): displacement from the side's start
    point (m), velocity (m/s), force (N) and the energy that came into the channel there (J).

    For the record only (the peer does not use them): the energy the channel gave out there
    (J), what the side's passivity controller took out (J), and whether the side found its
    peer silent this sample."""

    stamp_ns: int
    position: Vec3
    velocity: Vec3
    force: Vec3
    energy_in_j: float
    energy_out_j: float = 0.0
    dissipated_j: float = 0.0
    peer_silent: bool = False


def _rotate(R: tuple[Vec3, Vec3, Vec3], s: float, v: Vec3) -> Vec3:
    """``s R v``."""
    a, b, c = R
    x, y, z = v
    return (
        s * (a[0] * x + a[1] * y + a[2] * z),
        s * (b[0] * x + b[1] * y + b[2] * z),
        s * (c[0] * x + c[1] * y + c[2] * z),
    )


class _End:
    """What both ends share: the incoming line, the port's energy book, the mapping."""

    def __init__(
        self,
        teleop: TeleopSettings,
        channel: ChannelSettings,
        period_ns: int,
        salt: int,
        lost: Callable[[str], None],
        back: Callable[[], None],
    ) -> None:
        if channel.passivity and teleop.architecture == "position_position":
            raise ValueError(
                "channel.passivity is built for teleop.architecture position_force: under "
                "position_position the ports' efforts are not one port's"
            )
        self.teleop = teleop
        self.period_ns = period_ns
        self.dt = period_ns * 1e-9
        self.line: DelayLine[PortMessage] = DelayLine(channel, period_ns, salt, lost, back)
        self.clock = SampleClock(period_ns)  # this side's sample indices
        self.port = PassivityPort(self.dt, channel.passivity)
        self.origin: Vec3 | None = None  # the side's point at its first sample (m)
        self.peer_silent = False

    def receive(self, message: PortMessage) -> None:
        """A message of the other side came (in the order of its stamps)."""
        self.line.push(message.stamp_ns, message)

    def ready(self, stamp_ns: int) -> bool:
        """Lockstep: every message that can be due by this sample has come."""
        return self.line.complete(self.clock.index(stamp_ns))

    def _incoming(self, k: int) -> PortMessage | None:
        """The newest message due by sample ``k``, None while the peer is silent."""
        msg = self.line.take(k)
        if msg is not None:
            self.port.received(msg.energy_in_j)
        self.peer_silent = self.line.silent(k)
        return None if self.peer_silent else msg

    def _message(self, stamp_ns: int, position: Vec3, velocity: Vec3, force: Vec3) -> PortMessage:
        """This sample's message, with the port's energy book as it stands."""
        p = self.port
        return PortMessage(
            stamp_ns, position, velocity, force, p.e_in, p.e_out, p.dissipated_j, self.peer_silent
        )


class MasterEnd(_End):
    """The master's end: renders the slave's side as the master's wall force.

    Args:
        teleop: architecture, mapping, coupling.
        channel: the channel's settings (delay, jitter, loss, timeout, passivity).
        period_ns: the sample period (ns).
        axis: a 1-DOF master's axis (its frame): the rendered force is taken along it.
        lost, back: told when the slave falls silent and when it is back.
    """

    def __init__(
        self,
        teleop: TeleopSettings,
        channel: ChannelSettings,
        period_ns: int,
        axis: Vec3 | None = None,
        lost: Callable[[str], None] = _quiet,
        back: Callable[[], None] = _quiet,
    ) -> None:
        super().__init__(teleop, channel, period_ns, 1, lost, back)
        m = teleop.matrix
        self._R: tuple[Vec3, Vec3, Vec3] = tuple(tuple(r) for r in m.tolist())  # type: ignore[assignment]  # 3x3
        self._Rt: tuple[Vec3, Vec3, Vec3] = tuple(tuple(r) for r in m.T.tolist())  # type: ignore[assignment]  # 3x3
        self.axis = axis
        self.force_sent: Force = ZERO_FORCE  # the port's force this cycle (slave units, N)
        # what the master can render, in slave units: the port books no more (N)
        self._limit_n = (
            teleop.master_max_force_n / teleop.force_scale if teleop.force_scale > 0.0 else math.inf
        )
        self._ramp = max(1, math.ceil(channel.timeout_s * 1e9 / period_ns))  # samples
        self._since_back = self._ramp  # samples since the slave came back (full force)

    def cycle(self, stamp_ns: int, position: Vec3, velocity: Vec3) -> tuple[Force, PortMessage]:
        """Sample k's point (m) and velocity (m/s), master frame -> the wall force the master
        renders (N, master frame) and the message to the slave."""
        t = self.teleop
        if self.origin is None:
            self.origin = position
        o = self.origin
        disp = (position[0] - o[0], position[1] - o[1], position[2] - o[2])
        x = _rotate(self._R, t.position_scale, disp)
        v = _rotate(self._R, t.position_scale, velocity)
        msg = self._incoming(self.clock.index(stamp_ns))
        if msg is None:
            f: Force = ZERO_FORCE
            if self.peer_silent:  # its force comes back over the ramp
                self._since_back = 0
        else:
            if t.architecture == "position_force":
                f = msg.force
            else:
                k, b = t.coupling_n_per_m, t.coupling_n_s_per_m
                p, w = msg.position, msg.velocity
                f = (
                    k * (p[0] - x[0]) + b * (w[0] - v[0]),
                    k * (p[1] - x[1]) + b * (w[1] - v[1]),
                    k * (p[2] - x[2]) + b * (w[2] - v[2]),
                )
            if self._since_back < self._ramp:  # back after a silence: ramp the force in
                self._since_back += 1
                r = self._since_back / self._ramp
                f = (f[0] * r, f[1] * r, f[2] * r)
            f = limit_norm(f, self._limit_n)
        f = self.port.impedance(f, v)
        self.force_sent = f
        fw = _rotate(self._Rt, t.force_scale, f)
        a = self.axis
        if a is not None:
            s = fw[0] * a[0] + fw[1] * a[1] + fw[2] * a[2]
            fw = (s * a[0], s * a[1], s * a[2])
        return fw, self._message(stamp_ns, x, v, f)


class SlaveEnd(_End):
    """The slave's end: the point the slave tracks, from the master's delayed displacement.

    Args as ``MasterEnd`` (no axis); ``lost``/``back`` tell about the master.
    """

    def __init__(
        self,
        teleop: TeleopSettings,
        channel: ChannelSettings,
        period_ns: int,
        lost: Callable[[str], None] = _quiet,
        back: Callable[[], None] = _quiet,
    ) -> None:
        super().__init__(teleop, channel, period_ns, 0, lost, back)
        self.target: Vec3 = ZERO_FORCE  # the point the slave tracks (m, slave frame)
        self._disp: Vec3 = ZERO_FORCE  # the master's displacement the target last followed
        self.holding = False
        self._unbooked: Vec3 | None = None  # the velocity ``track`` sent, its power not booked

    @property
    def target_needs_force(self) -> bool:
        """The point to track depends on the sample's force: the passivity controller acts."""
        return self.port.enabled

    def cycle(
        self, stamp_ns: int, position: Vec3, velocity: Vec3, force: Force
    ) -> tuple[Vec3, PortMessage]:
        """Sample k's point (m), velocity (m/s) and contact force (N), slave frame -> the point
        to track and the message to the master."""
        target = self.track(stamp_ns, position, force)
        return target, self.message(stamp_ns, position, velocity, force)

    def track(self, stamp_ns: int, position: Vec3, force: Force | None = None) -> Vec3:
        """Sample k's point to track (m, slave frame), from its point (m) and, when
        ``target_needs_force``, its contact force (N); without it (``None``) the force is
        booked by ``message``, which must follow for the same sample."""
        if force is None and self.target_needs_force:
            raise ValueError("the passivity controller needs the sample's force")
        if self.origin is None:
            self.origin = self.target = position
        msg = self._incoming(self.clock.index(stamp_ns))
        if self.peer_silent:
            if not self.holding:  # hold where it is
                self.holding = True
                self.target = position
            v: Vec3 = ZERO_FORCE  # no flow: books nothing
            if force is not None:
                self.port.admittance(v, force)
        else:
            d = msg.position if msg is not None else self._disp
            if self.holding:  # back after a silence: go on from the held point, no jump
                self.holding = False
                self._disp = d
            d0 = self._disp
            T = self.dt
            v = ((d[0] - d0[0]) / T, (d[1] - d0[1]) / T, (d[2] - d0[2]) / T)
            if force is not None:
                v = self.port.admittance(v, force)
            p = self.target
            self.target = (p[0] + v[0] * T, p[1] + v[1] * T, p[2] + v[2] * T)
            self._disp = d
        self._unbooked = None if force is not None else v
        return self.target

    def forget(self) -> None:
        """The sample ``track`` took never gets its force (lost in real time): its power is not
        booked, as for a sample skipped whole, though its target moved (only without the
        passivity controller, which would have needed the force: the book is then an
        observer's)."""
        self._unbooked = None

    def message(self, stamp_ns: int, position: Vec3, velocity: Vec3, force: Force) -> PortMessage:
        """Sample k's message to the master, after ``track``: its point (m), velocity (m/s)
        and contact force (N), the port's energy book with the sample's power in it."""
        if self._unbooked is not None:  # the controller was off: the velocity went out as is
            self.port.admittance(self._unbooked, force)
            self._unbooked = None
        o = self.origin
        assert o is not None
        disp = (position[0] - o[0], position[1] - o[1], position[2] - o[2])
        return self._message(stamp_ns, disp, velocity, force)
