"""The teleoperation batch runner: master, channel and slave in-process, the node graph's cycle.

Per cycle k both devices report sample k, and each side runs what its nodes run:

- master: its observer on sample k (``haptic_dob.core.cycle.estimate``), its channel end
  (``MasterEnd.cycle``: the wall force from the slave's newest message), its haptic law
  (``CommandJoin``, as ``controller_node``: OL, CL or DOB rendering that force);
- slave: its observer on sample k (the contact force without a sensor), its channel end
  (``SlaveEnd.cycle``: the point to track from the master's newest message, the message back
  with the estimated or the measured force), its joint impedance (``SlaveController``);

then each end hands its message to the other's delay line, and both devices hold their command
over [k, k+1). Deterministic for the config's seeds; the lockstep graph reproduces it.
"""

from __future__ import annotations

import numpy as np

from haptic_dob.core.control import ImpedanceController
from haptic_dob.core.cycle import LoopCycle, estimate
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.slide import SlideModel
from haptic_dob.teleop.ends import MasterEnd, SlaveEnd
from haptic_dob.teleop.slave import SlaveController
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.result import TeleopResult, mapped_point, rendered_force

#: per-cycle 3-vectors recorded (slave frame unless said)
CART = (
    "master_point",  # the master's point mapped to the slave: start + scale R d_m (m)
    "slave_point",  # the slave's tool point, from its encoders (m)
    "target",  # the point the slave tracks (m)
    "contact",  # the true contact force on the slave (N)
    "estimate",  # the slave observer's estimate (N)
    "sensor",  # the slave's wrist sensor (N)
    "rendered",  # the master's wall force in slave units, R F_w / force_scale (N)
    "hand",  # the hand's true force on the master (N, master frame)
)
#: per-cycle scalars recorded
SCALARS = ("e_in_master", "e_out_master", "e_in_slave", "e_out_slave", "dissipated", "silent")


def run_teleop(config: TeleopConfig, cycles: int | None = None) -> TeleopResult:
    """Run ``config`` in-process for ``cycles`` cycles (default: duration_s * rate_hz)."""
    master, slave = config.master_device(), config.slave_device()
    n = config.loop.batch_cycles(cycles)
    period = master.period_ns
    dt = period * 1e-9
    m_model = config.model("master", "observer_node")
    m_obs = config.master_observer.build(m_model, dt)
    law_model = config.model("master", "controller_node")
    m_cycle = LoopCycle(
        VirtualWall(stiffness_n_per_m=0.0),
        m_obs,
        ImpedanceController(law_model, config.master_law),
        period,
    )
    s_obs = config.slave_observer.build(config.model("slave", "observer_node"), dt)
    s_ctl = SlaveController(config.model("slave", "slave_controller_node"), config.slave, dt)
    end_model = config.model("master", "channel_node")  # the master's axis, for a slide
    axis = tuple(float(a) for a in end_model.axis) if isinstance(end_model, SlideModel) else None
    m_end = MasterEnd(config.teleop, config.channel, period, axis)  # type: ignore[arg-type]  # 3 floats
    s_end = SlaveEnd(config.teleop, config.channel, period)
    sensor = config.teleop.force_source == "sensor"
    R = config.teleop.matrix
    sp, sf = config.teleop.position_scale, config.teleop.force_scale
    cart = {k: np.empty((n, 3)) for k in CART}
    scal = {k: np.empty(n) for k in SCALARS}
    q_slave = np.empty((n, slave.dof))
    tau_slave = np.empty((n, slave.dof))
    master_x = np.empty(n)
    master_v = np.empty(n)
    p_m0 = np.asarray(master.sample().ee_position)
    p_s0 = np.asarray(slave.sample().ee_position)
    for k in range(n):
        sm, ss = master.sample(), slave.sample()
        # master side: observer, channel end, haptic law
        f_m_est = estimate(m_obs, sm.q, sm.qd, sm.effort)
        f_w, to_slave = m_end.cycle(sm.stamp_ns, sm.ee_position, sm.ee_velocity)
        tau_m = m_cycle.command(sm.stamp_ns, sm.q, f_w, sm.wrench_measured, f_m_est)
        # slave side: observer, channel end, joint impedance
        f_hat = estimate(s_obs, ss.q, ss.qd, ss.effort)
        f_s = ss.wrench_measured if sensor else f_hat
        target, to_master = s_end.cycle(ss.stamp_ns, ss.ee_position, ss.ee_velocity, f_s)
        tau_s = s_ctl.command(np.asarray(ss.q), np.asarray(ss.qd), target)
        s_end.receive(to_slave)
        m_end.receive(to_master)
        # the record
        cart["master_point"][k] = mapped_point(R, sp, p_s0, p_m0, sm.ee_position)
        cart["slave_point"][k] = ss.ee_position
        cart["target"][k] = target
        cart["contact"][k] = slave.contact_force_true
        cart["estimate"][k] = f_hat
        cart["sensor"][k] = ss.wrench_measured
        cart["rendered"][k] = rendered_force(R, sf, f_w)
        cart["hand"][k] = sm.hand_force
        mp, sp_ = m_end.port, s_end.port
        scal["e_in_master"][k], scal["e_out_master"][k] = mp.e_in, mp.e_out
        scal["e_in_slave"][k], scal["e_out_slave"][k] = sp_.e_in, sp_.e_out
        scal["dissipated"][k] = mp.dissipated_j + sp_.dissipated_j
        scal["silent"][k] = 1.0 * m_end.peer_silent + 2.0 * s_end.peer_silent
        q_slave[k] = ss.q
        tau_slave[k] = tau_s
        master_x[k] = sm.q[0]
        master_v[k] = sm.qd[0]
        master.apply(tau_m)
        slave.apply(tau_s)
    return TeleopResult(
        config=config,
        t=np.arange(n) * dt,
        master_q=master_x,
        master_qd=master_v,
        slave_q=q_slave,
        slave_command=tau_slave,
        **cart,
        **scal,
    )
