"""An arm simulator of the tests' own, apart from the suite's models, for URDF observer checks.

What the suite's ``UrdfModel`` (and so its observer) does, this simulator does differently:

- the model: pinocchio's parse *without* its mimic joints (every joint independent); a mimic
  joint is coupled to its master here, by the multiplier and offset read from the URDF's XML;
- the dynamics: pinocchio's articulated-body algorithm (``aba``) where no joint is coupled, else
  ``(S^T M S)^-1`` of the coupled coordinates (the suite's observer uses CRBA and RNEA on
  pinocchio's mimic joints);
- the tip force: a spatial force on the tip's body (``fext``), not ``J^T F``;
- the state: pinocchio's configuration (``(cos, sin)`` for continuous joints), integrated on it by
  fourth-order Runge-Kutta with ``pinocchio.integrate``; the joint state it publishes is the angle.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence

import numpy as np
import pinocchio as pin


def _mimics(xml: str) -> dict[str, tuple[str, float, float]]:
    """Mimic joint -> (master, multiplier, offset), from the URDF text."""
    out = {}
    for joint in ET.fromstring(xml).iter("joint"):
        mimic = joint.find("mimic")
        if mimic is not None:
            out[joint.get("name", "")] = (
                mimic.get("joint", ""),
                float(mimic.get("multiplier", "1")),
                float(mimic.get("offset", "0")),
            )
    return out


class AbaArm:
    """The arm of ``xml`` moving in ``joints`` (every other joint held at zero), a force at the tip.

    Args:
        xml: the URDF text.
        tip_frame: where ``force_n`` (N, base axes) acts from ``force_at_s`` (s) on.
        joints: the coordinates, in the order of the efforts and joint states.
        start: their initial values (rad or m).
        dt: the sample period (s); ``substeps`` Runge-Kutta steps per period.
    """

    def __init__(
        self,
        xml: str,
        tip_frame: str,
        joints: Sequence[str],
        start: Sequence[float],
        force_n: Sequence[float],
        force_at_s: float,
        dt: float = 1e-3,
        substeps: int = 4,
    ) -> None:
        full = pin.buildModelFromXML(xml)  # no mimic joints: each joint on its own
        mimics = {m: v for m, v in _mimics(xml).items() if v[0] in joints}
        keep = set(joints) | set(mimics)
        lock = [i for i in range(1, full.njoints) if full.names[i] not in keep]
        self.model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
        self.data = self.model.createData()
        m = self.model
        body = pin.FrameType.BODY  # a link's frame, where a joint of the same name exists too
        self.fid = (
            m.getFrameId(tip_frame, body)
            if m.existFrame(tip_frame, body)
            else m.getFrameId(tip_frame)
        )
        self.tip_joint = m.frames[self.fid].parentJoint
        self.S = np.zeros((m.nv, len(joints)))  # pinocchio velocity from ours
        self.offset = np.zeros(m.nv)
        self.joint_ids = [m.getJointId(n) for n in joints]
        for ours, jid in enumerate(self.joint_ids):
            self.S[m.joints[jid].idx_v, ours] = 1.0
        for name, (master, mult, off) in mimics.items():
            iv = m.joints[m.getJointId(name)].idx_v
            self.S[iv, list(joints).index(master)] = mult
            self.offset[iv] = off
        self.coupled = bool(mimics)
        self.q = pin.integrate(m, pin.neutral(m), self.S @ np.asarray(start) + self.offset)
        self.v = np.zeros(m.nv)
        self.force = np.asarray(force_n, dtype=np.float64)
        self.force_at_s = force_at_s
        self.k = 0  # samples so far
        self.dt = dt
        self.h = dt / substeps
        self.substeps = substeps

    def angles(self) -> np.ndarray:
        """The coordinates as a joint state carries them (continuous joints: atan2 of the pair)."""
        out = []
        for jid in self.joint_ids:
            j = self.model.joints[jid]
            c = self.q[j.idx_q : j.idx_q + j.nq]
            out.append(math.atan2(c[1], c[0]) if j.nq == 2 else float(c[0]))
        return np.array(out)

    def velocities(self) -> np.ndarray:
        """The coordinates' velocities (rad/s or m/s)."""
        return np.array([self.v[self.model.joints[j].idx_v] for j in self.joint_ids])

    def tip_force(self, t: float) -> np.ndarray:
        """The force acting at the tip at time ``t`` (N, base axes)."""
        return self.force if t >= self.force_at_s else np.zeros(3)

    def _fext(self, q: np.ndarray, t: float) -> list[pin.Force]:
        m, d = self.model, self.data
        pin.framesForwardKinematics(m, d, q)
        p = d.oMf[self.fid].translation
        F = self.tip_force(t)
        world = pin.Force(F, np.cross(p, F))  # at the base origin, base axes
        fext = [pin.Force.Zero() for _ in range(m.njoints)]
        fext[self.tip_joint] = d.oMi[self.tip_joint].actInv(world)
        return fext

    def _accel(self, q: np.ndarray, v: np.ndarray, tau: np.ndarray, t: float) -> np.ndarray:
        m, d, S = self.model, self.data, self.S
        fext = self._fext(q, t)
        if not self.coupled:
            return np.asarray(pin.aba(m, d, q, v, S @ tau, fext)).copy()
        M = pin.crba(m, d, q)
        M = np.triu(M) + np.triu(M, 1).T
        bias = pin.rnea(m, d, q, v, np.zeros(m.nv), fext)
        return S @ np.linalg.solve(S.T @ M @ S, tau - S.T @ bias)

    def step(self, tau: Sequence[float]) -> None:
        """Hold ``tau`` (ours) over one period: Runge-Kutta 4 on the configuration."""
        m, h, u = self.model, self.h, np.asarray(tau, dtype=np.float64)
        for i in range(self.substeps):
            q, v, t = self.q, self.v, self.k * self.dt + i * h
            a1 = self._accel(q, v, u, t)
            v2 = v + 0.5 * h * a1
            a2 = self._accel(pin.integrate(m, q, 0.5 * h * v), v2, u, t + 0.5 * h)
            v3 = v + 0.5 * h * a2
            a3 = self._accel(pin.integrate(m, q, 0.5 * h * v2), v3, u, t + 0.5 * h)
            v4 = v + h * a3
            a4 = self._accel(pin.integrate(m, q, h * v3), v4, u, t + h)
            self.q = pin.integrate(m, q, h * (v + 2 * v2 + 2 * v3 + v4) / 6.0)
            self.v = v + h * (a1 + 2 * a2 + 2 * a3 + a4) / 6.0
        self.k += 1
