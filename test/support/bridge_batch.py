"""A bridge session in batch: a test driver's plant and semantics, the bridge's own cycle
(``haptic_dob.bridge``: ``StateReader``, ``BridgeLoop``) and the loop's stages
(``haptic_dob.core.cycle``), every command on time.

What a real-time session through ``bridge_node`` and a test driver does when every command
arrives before the driver's next tick (or, with ``late``, that share of them after it: this
process held up, the next state waiting in its queue; with ``crossing``, that share sent just
after the next tick, before its state could be heard), sample for sample: the driver ticks its plant
(``support.drivers.plants``) with the effort in force (a ros2_control driver writes the newest
command at its next cycle; a Touch driver applies the newest force on arrival while its white
button is held, here always), publishes its state (a Force Dimension's position, velocity and
effort; a Touch's positions only), the bridge hands the loop its sample and the loop's command
back to the driver. ``BridgeRecord`` holds what the loop's ``joint_states`` and
``wrench_estimate`` carried (what ``--record`` writes) beside the plant's truth.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from typing import Any

import numpy as np
from numpy.typing import NDArray

from haptic_dob.bridge.driver_settings import DriverSettings
from haptic_dob.bridge.loop import BridgeLoop, Send
from haptic_dob.bridge.settings import SafetySettings
from haptic_dob.bridge.state import StateReader
from haptic_dob.core.control import ImpedanceController, ImpedanceLaw
from haptic_dob.core.cycle import LoopCycle
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.excitation import Excitation
from haptic_dob.core.models.factory import build_model
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.runtime.params import build, node_view
from haptic_msgs_py.values import EffortCommand
from support.drivers.plants import TOUCH_MAX_FORCE_N, Plant

Arr = NDArray[np.float64]
TOUCH_JOINTS = ("waist", "shoulder", "elbow", "yaw", "pitch", "roll")


@dataclass(frozen=True)
class BridgeRecord:
    """Per driver state handed on (SI): the loop's joint states, the estimate, the truth."""

    joint_names: tuple[str, ...]
    stamps_ns: NDArray[np.int64]
    q: Arr  # as the bridge handed them on (the model's joints)
    qd: Arr  # the bridge's velocity
    effort: Arr  # the effort in force over [k-1, k) the bridge reported
    applied: Arr  # the joint effort the plant had over [k-1, k)
    estimate: Arr  # the observer's wrench (N)
    hand: Arr  # the plant's true hand force (N)
    tip: Arr  # the plant's tip from its encoders (m)
    counts: dict[str, float]

    def in_contact(self, wall: VirtualWall, settle_s: float = 2.0) -> tuple[float, float, float]:
        """Share of samples in contact after ``settle_s``, the RMS of the estimate's 3-D error
        against the true hand force there (N), and that force's span along the normal (N): the
        figure of ``test_point_mass_chain.py``."""
        t = (self.stamps_ns - self.stamps_ns[0]) * 1e-9
        keep = t >= settle_s
        depth = (self.tip[keep] - np.asarray(wall.position)) @ np.asarray(wall.normal)
        inside = depth > 0.0
        err = np.linalg.norm(self.estimate[keep][inside] - self.hand[keep][inside], axis=1)
        span = float(np.ptp(self.hand[keep][inside] @ np.asarray(wall.normal)))
        return float(inside.mean()), float(np.sqrt(np.mean(err * err))), span


def run_bridge(
    nodes: Mapping[str, Mapping[str, Any]],
    plant: Plant,
    seconds: float,
    late: float = 0.0,
    seed: int = 0,
    state_delay_s: float = 0.0,
    crossing: float = 0.0,
) -> BridgeRecord:
    """The session ``nodes`` (a bridge config's node sections) against ``plant`` for
    ``seconds`` of driver time, each state heard ``state_delay_s`` after its instant at the
    least (one machine's clock: the bridge is told the system time too), a command taken by the
    driver at the first tick after it was sent. Each command late with probability ``late``
    (``seed``): sent 1.3 periods after its state's instant, after the next state's instant, and
    that state heard only after it (it waited in the queue); or, with probability ``crossing``,
    sent half the state's delay after the next state's instant, before that state could be
    heard. Either way the driver takes it at the tick after. The rest are sent a tenth of a
    period after their state is heard."""
    v = node_view(nodes, "bridge_node")
    driver = DriverSettings.of(v)
    model = build_model(v)
    reader = StateReader(driver.state, driver.frame, model.joint_names, 1.0 / v["rate_hz"])
    safety = build(SafetySettings, v, "safety.").check()
    bridge = BridgeLoop(driver, safety, model, reader.driver_joints, v["rate_hz"])
    bridge.start()
    bridge.on_deadman(True, 0.0)  # held throughout (the white button: the driver's too)
    env, obs, ctl = (
        node_view(nodes, n) for n in ("environment_node", "observer_node", "controller_node")
    )
    observer = build(ObserverSettings, obs).build(build_model(obs), plant.period_ns * 1e-9)
    cycle = LoopCycle(
        build(VirtualWall, env),
        observer,
        ImpedanceController(build_model(ctl), build(ImpedanceLaw, ctl)),
        plant.period_ns,
        build(Excitation, env, "excitation."),
    )
    touch = driver.cartesian
    names = TOUCH_JOINTS if touch else reader.driver_joints
    held = np.zeros(3)  # the driver's newest command (ros2_control: elements; Touch: force)
    written = np.zeros(plant.dof)  # ros2_control: the command interfaces' values
    rows: list[tuple[Any, ...]] = []
    n = round(seconds * 1e9 / plant.period_ns)
    period = plant.period_ns * 1e-9
    rng = np.random.default_rng(seed)
    pending: Arr | None = None  # a late command on its way: the driver takes it next tick
    heard = 0.0  # when this process hears the next state (s)
    applied = np.zeros(plant.dof)
    for k in range(n + 1):
        if k > 0:
            if touch:
                F = held * min(1.0, TOUCH_MAX_FORCE_N / max(float(np.linalg.norm(held)), 1e-12))
                J = plant.model._jacobian(np.asarray(plant.sample().q))
                applied = J.T @ F  # a new array each tick
            else:
                applied = written.copy()
            plant.apply(applied.tolist())
        s = plant.sample()
        if not touch:
            written = held.copy()  # the controller's update writes the newest command
        if pending is not None:  # it came during [k, k+1): from the next tick on
            held, pending = pending, None
        if touch:
            q6 = (*s.q, 0.0, 0.0, 0.0)
            state = reader.joints(s.stamp_ns, names, q6, (), ())
        else:
            state = reader.joints(s.stamp_ns, names, s.q, s.qd, s.effort)
        t = k * period  # the state's instant
        at = max(t + state_delay_s, heard)  # its delay after its instant, or after a late command
        heard = t + period + state_delay_s
        sample, zero = bridge.on_state(state, at, s.stamp_ns + round((at - t) * 1e9))
        held = _sent(zero, held)
        if sample is None:
            continue
        _, f_est, tau = cycle.step(
            sample.stamp_ns,
            sample.q,
            sample.qd,
            sample.effort,
            sample.ee_position,
            sample.ee_velocity,
            (0.0, 0.0, 0.0),
        )
        command = EffortCommand(sample.stamp_ns, tuple(tau))
        draw = rng.random()
        if draw < late + crossing:  # it reaches the driver after the next state's instant
            sent = t + 1.3 * period if draw < late else t + period + 0.5 * state_delay_s
            send = bridge.on_command(command, sent)
            pending = None if send is None else np.array(send.values, dtype=np.float64)
            heard = max(heard, sent + 0.05 * period)  # the next state waited for it
        else:
            held = _sent(bridge.on_command(command, at + 0.1 * period), held)
        truth = (applied, f_est, s.hand_force, s.ee_position)
        rows.append((s.stamp_ns, sample.q, sample.qd, sample.effort, *truth))
    stamps, q, qd, effort, applied_, est, hand, tip = zip(*rows, strict=True)
    return BridgeRecord(
        tuple(model.joint_names),
        np.array(stamps, dtype=np.int64),
        *map(np.array, (q, qd, effort, applied_, est, hand, tip)),
        bridge.counts(),
    )


def _sent(send: Send | None, held: Arr) -> Arr:
    """What the driver holds after the bridge's ``send`` (if any)."""
    return held if send is None else np.array(send.values, dtype=np.float64)
