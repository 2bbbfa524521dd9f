"""Teleoperation's ROS-free parts: the slave's contact, the channel's delay line and passivity
control, the two ends, the slave's law and the momentum observer. Fast, in-process."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models import UrdfModel
from haptic_dob.core.observers.disturbance import DisturbanceObserver
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.observers.momentum import MomentumObserver
from haptic_dob.teleop.delay import DelayLine
from haptic_dob.teleop.ends import MasterEnd, SlaveEnd
from haptic_dob.teleop.passivity import PassivityPort
from haptic_dob.teleop.settings import ChannelSettings, TeleopSettings
from haptic_dob.teleop.slave import SlaveController, SlaveImpedance
from haptic_sim.arm.contact import TipContact
from haptic_sim.arm.device import ArmDeviceParams, SimulatedArm

ROOT = Path(__file__).resolve().parents[3]
ARM7 = ROOT / "config" / "urdf" / "arm7.urdf"
Q0 = [0.0, 0.5, 0.0, -1.5, 0.0, 1.0, 0.0]  # the tool points down, 0.3998 m up
PERIOD = 1_000_000
DOWN = (0.0, 0.0, -1.0)


# --- the contact ------------------------------------------------------------------------------
def test_the_contact_pushes_only_while_penetrating_and_never_pulls() -> None:
    wall = TipContact(VirtualWall(3000.0, 20.0, (0.0, 0.0, 0.39), DOWN))
    assert np.array_equal(wall.force(np.array([0.5, 0.0, 0.395]), np.zeros(3)), np.zeros(3))
    pressed = wall.force(np.array([0.5, 0.0, 0.388]), np.zeros(3))
    np.testing.assert_allclose(pressed, [0.0, 0.0, 3000.0 * 0.002], rtol=1e-12)
    # leaving fast: the damper would pull; the contact gives zero instead
    leaving = wall.force(np.array([0.5, 0.0, 0.389]), np.array([0.0, 0.0, 1.0]))
    assert np.array_equal(leaving, np.zeros(3))
    with pytest.raises(ValueError, match="one-sided"):
        TipContact(VirtualWall(3000.0, 0.0, (0.0, 0.0, 0.0), DOWN, two_sided=True))


def bounce(damping: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The 7-DOF arm without gravity or friction thrown down onto the table, then left alone:
    its energy (kinetic + the table's spring) and the contact force, per sample."""
    model = UrdfModel(ARM7, "tool", gravity=False)
    table = VirtualWall(3000.0, damping, (0.0, 0.0, 0.395), DOWN)
    dev = ArmDeviceParams(initial_position=Q0, encoder_resolution_rad=0.0, velocity="exact")
    arm = SimulatedArm(model, dev, substeps=2, contact=table)
    push = (model.jacobian(np.array(Q0)).T @ np.array([0.0, 0.0, -30.0])).tolist()
    energy, force, depth = [], [], []
    for k in range(600):
        arm.apply(push if k < 20 else [0.0] * 7)  # a push, then nothing: the table throws back
        p = model.forward_kinematics(arm.q)
        d = max(0.0, 0.395 - float(p[2]))
        energy.append(arm.kinetic_energy() + 0.5 * 3000.0 * d * d)
        force.append(arm.contact_force_true.copy())
        depth.append(d)
    return np.array(energy), np.array(force), np.array(depth)


@pytest.mark.parametrize("damping", [0.0, 20.0])
def test_the_contact_inside_the_sub_steps_is_passive_and_unilateral(damping: float) -> None:
    energy, force, depth = bounce(damping)
    touching = depth > 0.0
    assert touching.any() and not touching[-50:].all()  # it hit the table and came off it
    # never pulls: the force is along +z (out of the table) or zero, and zero off the table
    assert np.all(force[:, 2] >= 0.0) and np.all(force[~touching] == 0.0)
    assert np.allclose(force[:, :2], 0.0)
    after = energy[20:]  # no actuator from here on: the energy only goes down (or stays)
    rise = np.max(np.diff(after))
    if damping == 0.0:  # a spring: kept to the integrator's accuracy
        assert abs(after[-1] - after[0]) < 1e-3 * after[0], (after[0], after[-1])
    else:
        assert rise < 1e-6 * after[0] and after[-1] < 0.9 * after[0], (rise, after[0], after[-1])


# --- the passivity controller ----------------------------------------------------------------
vec = st.tuples(*[st.floats(-5.0, 5.0)] * 3)


@settings(max_examples=50, deadline=None)
@given(st.lists(st.tuples(vec, vec, st.floats(0.0, 0.01)), min_size=1, max_size=60))
def test_the_passivity_controller_never_gives_out_more_than_came_in(steps) -> None:
    for side in ("impedance", "admittance"):
        port = PassivityPort(1e-3, enabled=True)
        remote = 0.0
        for a, b, e in steps:
            remote += e
            port.received(remote)
            out = getattr(port, side)(a, b)
            assert all(math.isfinite(x) for x in out)
            assert port.e_out <= port.remote_in + 1e-12
        off = PassivityPort(1e-3, enabled=False)
        for a, b, _ in steps:
            assert getattr(off, side)(a, b) == a  # off: only books


def test_the_master_port_damps_only_the_excess() -> None:
    port = PassivityPort(1e-3, enabled=True)
    port.received(0.0005)  # 0.5 mJ came in at the other end
    # the master moves with the rendered force: 1 N x 1 m/s = 1 W, 1 mJ per sample
    f = port.impedance((1.0, 0.0, 0.0), (1.0, 0.0, 0.0))
    assert f[0] == pytest.approx(0.5)  # half the energy allowed: half the force
    assert port.e_out == pytest.approx(0.0005) and port.dissipated_j == pytest.approx(0.0005)
    f = port.impedance((-1.0, 0.0, 0.0), (1.0, 0.0, 0.0))  # against the motion: energy in
    assert f == (-1.0, 0.0, 0.0) and port.e_in == pytest.approx(0.001)


# --- the delay line --------------------------------------------------------------------------
def line(**kw) -> DelayLine[int]:
    return DelayLine(ChannelSettings(**kw), PERIOD, salt=0)


def test_a_constant_delay_delivers_each_message_half_the_round_trip_later() -> None:
    d = line(round_trip_delay_ms=20.0)
    assert d.delay == 10
    got = []
    for k in range(40):
        d.push(k * PERIOD, k)
        assert d.complete(k + 10)
        got.append(d.take(k))
    assert got[:10] == [None] * 10 and got[10:] == list(range(30))
    assert not d.silent(39)


def test_jitter_and_loss_are_seeded_bounded_and_keep_the_newest() -> None:
    def run(seed: int) -> list[int | None]:
        d = line(round_trip_delay_ms=4.0, jitter_ms=5.0, loss=0.2, seed=seed, timeout_s=0.05)
        out = []
        for k in range(2000):
            d.push(k * PERIOD, k)
            out.append(d.take(k))
        assert 300 < d.dropped < 500  # 20 % of 2000
        return out

    a, b, c = run(1), run(1), run(2)
    assert a == b and a != c  # the seed decides, and only it
    ages = [k - m for k, m in enumerate(a) if m is not None]
    assert min(ages) >= 2 and max(ages) <= 2 + 5 + 20  # delay + jitter (+ losses in a row)
    newest = [m for m in a if m is not None]
    assert newest == sorted(newest)  # a late arrival never replaces a newer message


def test_the_watchdog_counts_samples_since_the_last_arrival() -> None:
    d = line(round_trip_delay_ms=10.0, cut_at_s=0.1, timeout_s=0.02)
    silent_from = None
    for k in range(300):
        d.push(k * PERIOD, k)
        d.take(k)
        if d.silent(k) and silent_from is None:
            silent_from = k
    # the last message (sample 99) arrives at 104; silent once 20 samples passed since then
    assert silent_from == 104 + 21
    assert d.complete(299)  # a cut link holds nothing up in lockstep


# --- the two ends ----------------------------------------------------------------------------
def ends(**channel) -> tuple[MasterEnd, SlaveEnd]:
    teleop = TeleopSettings(
        rotation=(0.0, 0.0, 1.0, 0.0, 1.0, 0.0, -1.0, 0.0, 0.0), position_scale=2.0, force_scale=0.1
    )
    ch = ChannelSettings(**channel)
    return MasterEnd(teleop, ch, PERIOD, axis=(1.0, 0.0, 0.0)), SlaveEnd(teleop, ch, PERIOD)


def test_the_ends_map_position_forward_and_force_back_one_sample_late() -> None:
    master, slave = ends()
    p_s0 = (0.5, 0.0, 0.4)
    for k in range(5):
        x = 0.001 * k  # the master moves forward 1 mm per sample
        fw, to_slave = master.cycle(k * PERIOD, (x, 0.0, 0.0), (1.0, 0.0, 0.0))
        target, to_master = slave.cycle(k * PERIOD, p_s0, (0.0, 0.0, 0.0), (0.0, 0.0, 10.0))
        slave.receive(to_slave)
        master.receive(to_master)
        # the slave tracks the master's displacement of one sample earlier, doubled, downward
        assert target == pytest.approx((0.5, 0.0, 0.4 - 0.002 * max(k - 1, 0)))
        # the master renders a tenth of the slave's force, back along its axis
        assert fw == pytest.approx((-1.0, 0.0, 0.0) if k >= 1 else (0.0, 0.0, 0.0))


def test_a_silent_peer_zeroes_the_master_force_and_the_slave_holds() -> None:
    master, slave = ends(round_trip_delay_ms=2.0, cut_at_s=0.05, timeout_s=0.005)
    for k in range(100):
        here = (0.5, 0.0, 0.4 - 0.0001 * k)  # the slave still drifts down
        fw, to_slave = master.cycle(k * PERIOD, (0.001 * k, 0.0, 0.0), (1.0, 0.0, 0.0))
        target, to_master = slave.cycle(k * PERIOD, here, (0.0, 0.0, 0.0), (0.0, 0.0, 5.0))
        slave.receive(to_slave)
        master.receive(to_master)
        if k == 56:  # the last message (49) arrived at 50: silent after 5 samples more
            assert master.peer_silent and slave.peer_silent and fw == (0.0, 0.0, 0.0)
            held = target
            assert held == pytest.approx(here)
        if k > 56:
            assert target == held and fw == (0.0, 0.0, 0.0)
        if 50 <= k < 56:
            assert not master.peer_silent


def test_after_a_silence_the_slave_goes_on_from_where_it_held_and_the_force_ramps_back() -> None:
    """A 20-sample outage (all messages lost) while the master moves 1 mm per sample: back, the
    slave's target moves on by one sample of the master's motion, not the outage's 20 mm, and
    the master's force comes back linearly over the timeout."""
    master, slave = ends(round_trip_delay_ms=2.0, timeout_s=0.005)
    here = (0.5, 0.0, 0.4)
    targets, forces = [], []
    for k in range(80):
        fw, to_slave = master.cycle(k * PERIOD, (0.001 * k, 0.0, 0.0), (1.0, 0.0, 0.0))
        target, to_master = slave.cycle(k * PERIOD, here, (0.0, 0.0, 0.0), (0.0, 0.0, 10.0))
        if not 30 <= k < 50:  # the outage: every message of samples 30..49 is lost
            slave.receive(to_slave)
            master.receive(to_master)
        targets.append(target[2])
        forces.append(fw[0])
    assert slave.holding is False and not master.peer_silent
    held = targets[40]  # silent by then (the last message, 29, arrived at 30; 5 samples + 1)
    assert targets[49] == held  # held through the outage
    steps = np.diff(targets[50:60])
    assert np.all(np.abs(steps) <= 0.002 + 1e-12)  # one sample of the master's motion (x2), no jump
    assert abs(targets[51] - held) < 0.005  # not the outage's 40 mm (20 mm doubled)
    ramp = forces[51:57]  # the first message back is due at 51: 1/5, 2/5 ... of the full -1 N
    assert ramp == pytest.approx([-0.2, -0.4, -0.6, -0.8, -1.0, -1.0])
    assert forces[45] == 0.0


def test_passivity_control_is_refused_for_position_position() -> None:
    teleop = TeleopSettings(architecture="position_position")
    with pytest.raises(ValueError, match="position_force"):
        MasterEnd(teleop, ChannelSettings(passivity=True), PERIOD)
    with pytest.raises(ValueError, match="position_force"):
        SlaveEnd(teleop, ChannelSettings(passivity=True), PERIOD)


def test_the_master_port_books_no_more_than_the_master_can_render() -> None:
    """A 100 N slave force with force_scale 0.1 asks 10 N of a 4 N master: the port's force (slave
    units) is limited to 40 N, the force the master renders."""
    master, slave = ends()
    for k in range(3):
        fw, _ = master.cycle(k * PERIOD, (0.0, 0.0, 0.0), (1.0, 0.0, 0.0))
        _, to_master = slave.cycle(k * PERIOD, (0.5, 0.0, 0.4), (0.0, 0.0, 0.0), (0.0, 0.0, 100.0))
        master.receive(to_master)
    assert master.force_sent == pytest.approx((0.0, 0.0, 40.0))
    assert fw == pytest.approx((-4.0, 0.0, 0.0))


def test_the_delay_rounds_half_up_and_reports_what_it_simulates() -> None:
    assert ChannelSettings(round_trip_delay_ms=5.0).delay_samples(PERIOD) == 3
    assert ChannelSettings(round_trip_delay_ms=5.0).simulated_round_trip_ms(PERIOD) == 6.0
    assert ChannelSettings(round_trip_delay_ms=25.0).delay_samples(PERIOD) == 13
    assert ChannelSettings(round_trip_delay_ms=50.0).simulated_round_trip_ms(PERIOD) == 50.0


# --- the slave's law -------------------------------------------------------------------------
def test_the_slave_law_holds_its_start_and_has_every_mode_at_the_bandwidth() -> None:
    model = UrdfModel(ARM7, "tool")
    ctl = SlaveController(model, SlaveImpedance(bandwidth_hz=20.0), 1e-3)
    q0 = np.array(Q0)
    tau = ctl.command(q0, np.zeros(7), tuple(model.forward_kinematics(q0)))
    np.testing.assert_allclose(tau, model.gravity(q0), atol=1e-9)
    # K = D w^2: the loop's modes D^-1 K all at (2 pi 20)^2
    eig = np.linalg.eigvals(np.linalg.solve(model.mass_matrix(q0), ctl.K)).real
    np.testing.assert_allclose(eig, (2 * math.pi * 20.0) ** 2, rtol=1e-9)
    with pytest.raises(ValueError, match="7 values"):
        SlaveController(model, SlaveImpedance(stiffness_n_m_per_rad=[1.0, 2.0]), 1e-3)


# --- the momentum observer --------------------------------------------------------------------
def test_the_momentum_observer_finds_a_tip_force_with_one_lag_on_every_joint() -> None:
    """The 7-DOF arm swinging under gravity compensation, a 5 N tip force from 0.3 s: both
    observers settle on it; the momentum observer's lag is 1/K whatever the joint's inertia."""
    model = UrdfModel(ARM7, "tool")
    dev = ArmDeviceParams(
        initial_position=Q0,
        encoder_resolution_rad=0.0,
        velocity="exact",
        external_force_n=(0.0, 3.0, -4.0),
        external_force_at_s=0.3,
    )
    arm = SimulatedArm(model, dev, substeps=4)
    mo = ObserverSettings(gain=100.0, kind="momentum").build(model, 1e-3)
    dob = DisturbanceObserver(model, 1000.0, 1e-3)
    assert isinstance(mo, MomentumObserver)
    ctl = SlaveController(model, SlaveImpedance(bandwidth_hz=5.0), 1e-3)
    est = []
    for k in range(800):
        s = arm.sample()
        q, qd = np.array(s.q), np.array(s.qd)
        mo.update(q, qd, s.effort)
        dob.update(q, qd, s.effort)
        est.append(mo.wrench(q))
        wobble = 0.1 * math.sin(2 * math.pi * 1.5 * k * 1e-3)
        arm.apply(ctl.joint_command(q, qd, np.array(Q0) + wobble))
    est = np.array(est)
    np.testing.assert_allclose(est[250], 0.0, atol=0.01)  # moving, no force yet
    # 1/K = 10 ms: 63 % of the step after 10 ms; then within 2 % of the 5 N while swinging (the
    # force's joint effort J^T F changes as the arm moves, and each estimate lags it)
    np.testing.assert_allclose(est[310, 1:], [3.0 * 0.63, -4.0 * 0.63], atol=0.15)
    np.testing.assert_allclose(est[400:], np.tile([0.0, 3.0, -4.0], (400, 1)), atol=0.1)
    np.testing.assert_allclose(dob.wrench(np.array(arm.sample().q)), [0.0, 3.0, -4.0], atol=0.1)


def test_the_ends_count_samples_of_system_clock_stamps_as_of_lockstep_stamps() -> None:
    """Real-time devices stamp with the system clock when they take a sample (a period apart,
    give or take their wake-up jitter, each side from its own start): each end counts the
    whole periods since a side's first stamp, so a cut link, the delay and the watchdog come at
    the same samples as with lockstep's ``k * T`` stamps (``cut_at_s`` from the start, not from
    1970)."""
    rng = np.random.default_rng(3)
    runs = []
    for wall in (False, True):
        master, slave = ends(round_trip_delay_ms=4.0, cut_at_s=0.05, timeout_s=0.005)
        t_m, t_s = (1_790_000_000_000_123_456, 1_790_000_000_003_400_000) if wall else (0, 0)
        out = []
        for k in range(100):
            jitter = rng.integers(0, 4 * PERIOD // 10, size=2) if wall else (0, 0)
            fw, to_slave = master.cycle(
                t_m + k * PERIOD + int(jitter[0]), (0.001 * k, 0.0, 0.0), (1.0, 0.0, 0.0)
            )
            here = (0.5, 0.0, 0.4 - 0.0001 * k)
            target, to_master = slave.cycle(
                t_s + k * PERIOD + int(jitter[1]), here, (0.0, 0.0, 0.0), (0.0, 0.0, 5.0)
            )
            slave.receive(to_slave)
            master.receive(to_master)
            out.append((fw, target, master.peer_silent, slave.peer_silent))
        runs.append(out)
    assert runs[0] == runs[1]
    assert runs[1][40][2] is False and runs[1][99][2] is True  # the cut (50) came, at its sample


@pytest.mark.parametrize("passivity", [False, True])
def test_the_slaves_point_tracked_before_its_force_is_the_whole_cycles(passivity: bool) -> None:
    """The slave's end in two steps (``track`` on the sample's point, then ``message`` once the
    force is here: what the channel node does, so the slave's command does not wait for its
    estimate) gives the one-step cycle's point, messages and energy book exactly, through an
    outage; with the passivity controller on, the point needs the force."""
    rng = np.random.default_rng(3)
    master, whole = ends(round_trip_delay_ms=2.0, timeout_s=0.005, passivity=passivity)
    _, split = ends(round_trip_delay_ms=2.0, timeout_s=0.005, passivity=passivity)
    for k in range(120):
        here = tuple(float(x) for x in rng.normal(0.0, 0.01, 3) + np.array([0.5, 0.0, 0.4]))
        velocity, force = tuple(rng.normal(0.0, 0.1, 3)), tuple(rng.normal(0.0, 5.0, 3))
        _, to_slave = master.cycle(k * PERIOD, (0.001 * k, 0.0, 0.0), (1.0, 0.0, 0.0))
        target, to_master = whole.cycle(k * PERIOD, here, velocity, force)
        if passivity:
            with pytest.raises(ValueError, match="needs the sample's force"):
                split.track(k * PERIOD, here)
        assert split.track(k * PERIOD, here, None if not passivity else force) == target
        assert split.message(k * PERIOD, here, velocity, force) == to_master
        if not 60 <= k < 80:
            for end in (whole, split):
                end.receive(to_slave)
            master.receive(to_master)
    assert split.port.e_in == whole.port.e_in > 0.0 and split.port.e_out == whole.port.e_out
    assert (whole.port.dissipated_j > 0.0) == passivity
