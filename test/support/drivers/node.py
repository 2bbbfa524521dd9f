"""A test driver: a real driver's topics over a simulated plant, on the wall clock, truth kept.

``python test/support/drivers/node.py CONFIG.json`` runs one driver until SIGINT/SIGTERM, then
writes ``truth.json`` (the plant's hidden parameters, counts, its last command) and
``series.npz`` (per cycle and per command) into the config's ``out`` directory. Config keys:
``kind`` (``fd``, ``touch``, ``arm``), ``rate_hz``, ``seed``, ``out``, ``hand``,
``hand_direction``, ``button`` and ``inkwell`` (touch), ``table_z`` (arm), ``rt_priority``
(``realtime``); test controls in its namespace: ``test/pause`` (``Float64``: no state for that
many seconds) and ``test/button`` (``Bool``). A Touch's stylus rests until it is taken
(``_taken``: the first force in the inkwell; a heard press with a hand, ``hand_start_ns``).

Tick k's instant is the first tick's plus k periods, and its state is stamped with it (when its
positions are true, as a real driver's stamp is). ``DriverNode._tick`` says what a tick does.
Command k is on time when it answers state k and DDS received it before tick k+1's instant
(``within_period``: its first answer came within a period of the state going out)."""

from __future__ import annotations

import json
import math
import os
import random
import sys
import time
from collections import deque
from pathlib import Path
from typing import Any

import numpy as np
from rclpy.context import Context
from std_msgs.msg import String

sys.path.insert(0, str(Path(__file__).resolve().parents[2]))  # ``support`` when run as a file

from haptic_dob.runtime.latency import LatencyHistogram
from haptic_dob.runtime.ros.spin import LoopNode, run_nodes
from haptic_msgs_py.ros.raw import raw_subscription
from haptic_msgs_py.stamps import period_ns
from support.drivers import plants
from support.drivers.speak import LATCHED, Ros2Control, Touch, instant_ns

TICKING = "ticking"  # the driver's first line once it ticks (``run.start`` waits for it)
ARM_JOINTS = tuple(f"joint{i}" for i in range(1, 8))
GRIPPER = "gripper_finger_joint"  # an extra joint the arm's model does not have
FD_JOINTS = ("fd_x", "fd_y", "fd_z")
#: periods a late tick steps the plant through unseen (``on_wakeup``); a longer stall moves the
#: grid on, the plant held
CATCH_UP = 20
#: touch: when in a period (its shares) the driver looks for the answer to its newest state, to
#: step the plant on it then rather than at the next instant, before that state goes out; on
#: one CPU it does not look (each look's wakeup would take the loop's CPU)
LOOKS = (0.3, 0.5, 0.7, 0.85)


class DriverNode(LoopNode):
    """One test driver (``kind`` of the config) ticking its plant on the wall clock."""

    def __init__(self, cfg: dict[str, Any], context: Context) -> None:
        self.kind = cfg["kind"]
        super().__init__(f"{self.kind}_driver", context=context)
        self.cfg = cfg
        rate = float(cfg["rate_hz"])
        seed = int(cfg.get("seed", 0))
        self.period_ns = period_ns(rate)
        self.period_s = self.period_ns * 1e-9
        hand = cfg.get("hand", {"behaviour": "none"})
        ns = {"fd": "/fd", "touch": "/touch", "arm": "/arm"}[self.kind]
        self.plant: Any
        direction = tuple(cfg.get("hand_direction", (0.0, 0.0, -1.0)))
        if self.kind == "fd":
            self.plant = plants.point_mass(rate, seed, hand, direction)
            self.io: Any = Ros2Control(self, ns, "fd_controller", FD_JOINTS, FD_JOINTS, self._got)
            self.names = FD_JOINTS
        elif self.kind == "arm":
            self.plant = plants.arm7(rate, seed, float(cfg.get("table_z", 0.39)))
            assert self.plant.model.joint_names == ARM_JOINTS
            shuffled = [*ARM_JOINTS, GRIPPER]
            random.Random(seed).shuffle(shuffled)
            self.names = tuple(shuffled)
            self.io = Ros2Control(self, ns, "effort_controller", self.names, ARM_JOINTS, self._got)
            pub = self.create_publisher(String, f"{ns}/robot_description", LATCHED)
            pub.publish(String(data=(plants.ROOT / "config" / "urdf" / "arm7.urdf").read_text()))
        else:
            self.plant = plants.touch(rate, seed, hand, direction)
            self.io = Touch(self, ns, self._got)
            self.names = Touch.JOINTS
            raw_subscription(
                self, "std_msgs/msg/Bool", f"{ns}/test/button", self._on_button, LATCHED
            )
        raw_subscription(self, "std_msgs/msg/Float64", f"{ns}/test/pause", self._on_pause, LATCHED)
        self._button = bool(cfg.get("button", False))
        self._hand_on = self.kind == "touch" and self.plant.device.hand.active
        #: touch: the stylus at rest (the plant does not step) until it is taken (``_taken``)
        self._resting = self.kind == "touch" and (bool(cfg.get("inkwell")) or self._hand_on)
        self.hand_start_ns = -1  # the instant the plant first stepped from (-1: not yet)
        self._written = tuple(0.0 for _ in range(self.plant.dof))  # effort in force (plant joints)
        self._force = np.zeros(3)  # touch: the Cartesian force in force (base frame)
        self.deadline = time.monotonic() + 0.2
        self.paused_until = 0.0
        self._looks: list[float] = []  # touch: monotonic s of this period's looks still to come
        self._look_at = LOOKS if len(os.sched_getaffinity(0)) >= 2 else ()
        self._ahead = False  # touch: the plant stepped over this period on its state's answer
        self._k = -1  # ticks done (sample index)
        self._n = 0  # the grid instant of the next tick (periods from the first)
        self._t0_ns = 0  # the system clock at the first tick's instant: the grid's origin
        self._stamp = 0  # the newest state's stamp
        self._sent_at: dict[int, int] = {}  # stamp -> system ns it went out, until answered
        self._answered = -1  # the newest stamp a command answered on time
        self.on_time = self.late = self.missed_ticks = self.states = 0
        #: stamps of the states since the last on-time command: late once a command answers
        #: one of them or a newer state (the loop was still answering, behind); the rest, after
        #: the loop's last answer, are its end
        self._unanswered: deque[int] = deque()
        self._marked = -1  # the newest state counted unanswered
        #: states whose first answer came within a period of the state going out: on time for
        #: a driver that publishes at its instant (this one is late at times)
        self.within_period = 0
        #: the first state answered on time, the last state first answered from it on
        self._answered_from, self._answered_to = 2**63, -1
        self.latency = LatencyHistogram()  # s, a state going out -> its first answer received
        #: per tick: stamp, monotonic s, went out (1; 0: the test's pause; -1: an overrun skipped
        #: it), q..., effort..., hand (3), tip (3)
        self.ticks: list[tuple[float, ...]] = []
        self.commands: list[tuple[float, ...]] = []  # arrival (monotonic), stamp, values...
        self.tick_stamps: list[int] = []  # each tick's stamp, exact (ns)
        self.tick_late: list[float] = []  # each tick's processing after its instant (s)
        #: each published state's going out after its instant (s): a Touch's physics is on it
        self.out_late: list[float] = []
        self.answered: list[int] = []  # the stamp each command answers, exact (-1: none)
        self.last_command: tuple[float, ...] = ()

    # --- inputs ------------------------------------------------------------------------------
    def _got(self, stamp_ns: int | None, values: tuple[float, ...], received_ns: int) -> None:
        """A command taken (``speak.Inbox``), received at ``received_ns`` (system clock)."""
        arrival = time.monotonic() - (time.time_ns() - received_ns) * 1e-9
        self.last_command = values
        self.commands.append((arrival, float(-1 if stamp_ns is None else stamp_ns), *values))
        self.answered.append(-1 if stamp_ns is None else stamp_ns)
        if stamp_ns == self._stamp and self._answered != self._stamp:
            self._answered = self._stamp
            self.on_time += 1
            self.late += len(self._unanswered)
            self._unanswered.clear()
            self._answered_from = min(self._answered_from, stamp_ns)
        elif stamp_ns is not None:  # a late answer: the states up to it were late, not the end
            while self._unanswered and self._unanswered[0] <= stamp_ns:
                self._unanswered.popleft()
                self.late += 1
        sent = None if stamp_ns is None else self._sent_at.pop(stamp_ns, None)
        if stamp_ns is not None and sent is not None:  # the state's first answer
            age_s = (received_ns - sent) * 1e-9
            self.latency.add(age_s)
            if stamp_ns >= self._answered_from:  # counted as on time is: from the first one
                self._answered_to = max(self._answered_to, stamp_ns)
                self.within_period += age_s < self.period_s

    def _on_button(self, msg: Any) -> None:
        self._button = bool(msg.data)

    def _on_pause(self, msg: Any) -> None:
        self.paused_until = time.monotonic() + float(msg.data)

    # --- the cycle ---------------------------------------------------------------------------
    def next_wakeup(self) -> float | None:
        return min(self._looks[0], self.deadline) if self._looks else self.deadline

    def on_wakeup(self, now: float) -> None:
        if self._looks and now < self.deadline:
            self._look(now)
            return
        if self._k < 0:
            self.get_logger().info(
                f"{TICKING} at {self.cfg['rate_hz']} Hz under {self.cfg.get('scheduling')}"
            )
            self._t0_ns = instant_ns(self.deadline)
        behind = int((now - self.deadline) / self.period_s)  # periods whose tick is past too
        if behind > CATCH_UP:  # a long stall: the grid skips the rest (lost; the plant holds)
            self.missed_ticks += behind - CATCH_UP
            self._n += behind - CATCH_UP
            self.deadline += (behind - CATCH_UP) * self.period_s
            behind = CATCH_UP
        # a real driver skips the cycles it overran, it does not run them back to back: Jazzy's
        # controller_manager (``overruns.manage``, on by default) moves its next cycle to the
        # grid's next instant, as rclcpp's timers and rates do. The device moves on meanwhile
        for _ in range(behind):
            self._tick(now, publish=False, missed=True)
        self._tick(now, publish=now >= self.paused_until)

    def _tick(self, now: float, publish: bool, missed: bool = False) -> None:
        """The cycle at grid instant ``self._n`` (deadline ``self.deadline``), processed at
        monotonic ``now``: first the commands DDS received before that instant (``Inbox``: a
        real driver's update does not wait for a late Python tick), then the state at the
        instant out (``publish``), the controller's update. ros2_control (fd, arm): the plant
        already stepped over the period before the instant at the end of the last tick, with
        the command written then, as the device moves on its own while the driver waits; then
        it steps over the next period with this update's command. Touch: the newest force acts
        over the period before the instant: the plant stepped on the answer to the last state
        when ``_look`` found it, else it steps now. A ``missed`` tick (a cycle the driver overran)
        only moves the plant through its period with the command in force: no state goes out
        and the controller's update does not run."""
        stamp = self._t0_ns + self._n * self.period_ns
        self.io.receive(stamp)  # the stamp is the tick's instant on the system clock
        answered = (self._answered, self._marked)
        if not missed and self._k >= 0 and self.on_time and self._stamp not in answered:
            self._unanswered.append(self._stamp)
            self._marked = self._stamp
        self._looks = []
        if self.kind == "touch" and self._k >= 0 and not self._ahead:
            self._step_touch(stamp - self.period_ns)
        self._ahead = False
        self._k += 1
        s = self.plant.sample()
        if self.kind == "touch" and not missed:
            self.io.press(self._button, stamp)
        if publish:
            self._publish(stamp, s)
        if (self.kind == "fd" or self.kind == "arm") and not missed:
            self._written = self.io.update()  # the controller's update: acts from this tick on
        applied = self._force if self.kind == "touch" else s.effort
        went = -1.0 if missed else float(publish)  # out, held by the test's pause, skipped
        row = (stamp, now, went, *s.q, *applied, *s.hand_force, *s.ee_position)
        self.ticks.append(row)
        self.tick_stamps.append(stamp)
        self.tick_late.append(now - self.deadline)
        self.missed_ticks += now - self.deadline > self.period_s
        self._n += 1
        self.deadline += self.period_s
        if self.kind == "touch" and publish:
            at = self.deadline - self.period_s
            self._looks = [t for t in (at + f * self.period_s for f in self._look_at) if t > now]
        self.plant.prepare()
        if self.kind != "touch":  # the period to the next instant, ahead of it
            self.plant.apply(self._effort())

    def _step_touch(self, start_ns: int) -> None:
        """Touch: the plant over the period from instant ``start_ns`` with the newest force."""
        effort = self._effort()
        self._resting = self._resting and not self._taken()
        if not self._resting:
            self.plant.apply(effort)
            if self.hand_start_ns < 0:
                self.hand_start_ns = start_ns

    def _look(self, now: float) -> None:
        """Touch, at monotonic ``now`` within a period: take the forces DDS received so far;
        the newest state's answer among them steps the plant over the period at once (a real
        driver's next state is read, not computed: it goes out at its instant). A force that
        comes after that step acts from the next period."""
        self._looks = [t for t in self._looks if t > now]
        self.io.receive(time.time_ns())
        if self._answered == self._stamp:
            self._step_touch(self._stamp)
            self._ahead = True
            self._looks = []

    def _publish(self, stamp: int, s: Any) -> None:
        self.out_late.append(time.monotonic() - self.deadline)
        self._stamp = stamp
        self._sent_at[stamp] = time.time_ns()
        if len(self._sent_at) > 256:  # states never answered (a pause of the loop's commands)
            del self._sent_at[next(iter(self._sent_at))]
        self.states += 1
        if self.kind == "touch":
            self.io.publish(stamp, s.q)
        elif self.kind == "fd":
            self.io.publish(stamp, self.names, s.q, s.qd, s.effort)
        else:
            by_name = dict(zip(ARM_JOINTS, zip(s.q, s.qd, s.effort, strict=True), strict=True))
            by_name[GRIPPER] = (0.04, 0.0, 0.0)
            q, qd, e = zip(*(by_name[n] for n in self.names), strict=True)
            self.io.publish(stamp, self.names, q, qd, e)

    def _taken(self) -> bool:
        """Touch: the stylus leaves its rest: with a hand, once the white button is held and its
        press went out to a matched reader (the bridge's dead-man, which a press it missed would
        leave released: the test presses again); in the inkwell, at the first force."""
        if self._hand_on:  # (``button`` held from the start: no press to hear)
            held_from_start = bool(self.cfg.get("button", False))
            return bool(self.io.buttons[self.io.WHITE]) and (self.io.press_heard or held_from_start)
        return any(self._force)

    def _effort(self) -> tuple[float, ...]:
        """The plant's joint effort over the coming period, the driver's way."""
        if self.kind == "fd":
            return self._written
        if self.kind == "arm":  # as a Franka: the commanded torque rides on the robot's own
            by_name = dict(zip(self.io.command_joints, self._written, strict=True))  # gravity
            g = self.plant.gravity()  # compensation
            return tuple(by_name[n] + gi for n, gi in zip(ARM_JOINTS, g, strict=True))
        # the drivers' force_feedback is in their pose frame, the URDF's base frame (speak.py)
        F = np.array(self.io.gated_force)
        norm = float(np.linalg.norm(F))
        if norm > plants.TOUCH_MAX_FORCE_N:
            F *= plants.TOUCH_MAX_FORCE_N / norm
        self._force = F
        J = self.plant.model._jacobian(np.asarray(self.plant.sample().q))
        return tuple((J.T @ F).tolist())

    # --- the end -------------------------------------------------------------------------------
    def _states_between(self, first_ns: int, last_ns: int) -> int:
        """States published with stamps from ``first_ns`` to ``last_ns``."""
        return sum(
            1
            for row, st in zip(self.ticks, self.tick_stamps, strict=True)
            if row[2] > 0 and first_ns <= st <= last_ns
        )

    @staticmethod
    def _ms(values: list[float], pct: float) -> float:
        """A percentile of ``values`` (s), in ms (NaN: none)."""
        return float(np.percentile(values, pct)) * 1e3 if values else math.nan

    def on_shutdown(self) -> None:
        self.io.receive(None)  # the last commands that came (a bridge's zero on its way out)
        self.io.inbox.close()
        out = Path(self.cfg["out"])
        out.mkdir(parents=True, exist_ok=True)
        counts = {
            "states": self.states,
            "ticks": self._k,
            "commands": len(self.commands),
            "commands_on_time": self.on_time,
            "commands_late": self.late,  # up to the loop's last answer: its end is not late
            "ticks_after_last_command": len(self._unanswered),
            "commands_within_period": self.within_period,
            "states_answered_span": self._states_between(self._answered_from, self._answered_to),
            "missed_ticks": self.missed_ticks,
            "latency_p50_ms": self.latency.percentile(50) * 1e3,
            "latency_p99_ms": self.latency.percentile(99) * 1e3,
            "tick_late_p50_ms": self._ms(self.tick_late, 50),
            "tick_late_p99_ms": self._ms(self.tick_late, 99),
            "state_out_late_p50_ms": self._ms(self.out_late, 50),
            "state_out_late_p99_ms": self._ms(self.out_late, 99),
            "nonfinite_dropped": self.io.nonfinite_dropped,
            "size_errors": getattr(self.io, "size_errors", 0),
        }
        truth = {
            "kind": self.kind,
            "rate_hz": self.cfg["rate_hz"],
            "scheduling": self.cfg.get("scheduling", "default scheduling"),
            "plant": self.plant.truth(),
            "counts": counts,
            "hand_start_ns": self.hand_start_ns,
            "last_command": list(self.last_command),
            "names": list(self.names),
        }
        (out / "truth.json").write_text(json.dumps(truth, indent=2, default=float))
        np.savez(
            out / "series.npz",
            ticks=np.array(self.ticks, dtype=np.float64),
            commands=np.array(self.commands, dtype=np.float64),
            tick_stamps=np.array(self.tick_stamps, dtype=np.int64),
            tick_late=np.array(self.tick_late, dtype=np.float64),
            answered=np.array(self.answered, dtype=np.int64),
            dof=self.plant.dof,
        )


def realtime(priority: int) -> str:
    """SCHED_FIFO ``priority`` for this process (0: none), as a controller manager runs its
    loop, where it may use more than one CPU; what it runs under (the threads started after
    inherit it). On one CPU it keeps default scheduling: this Python driver's tick (the plant's
    physics) takes a few hundred us, a real driver's tens, and under SCHED_FIFO it would hold
    the loop off the only CPU for that long at every tick."""
    if priority <= 0:
        return "default scheduling"
    if len(os.sched_getaffinity(0)) < 2:
        return "default scheduling (one CPU)"
    try:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    except OSError as exc:
        return f"default scheduling (SCHED_FIFO {priority} refused: {exc.strerror})"
    return f"SCHED_FIFO {priority}"


def main(argv: list[str]) -> int:
    """Run the driver of the config file ``argv[1]`` until a signal."""
    cfg = json.loads(Path(argv[1]).read_text())
    cfg["scheduling"] = realtime(int(cfg.get("rt_priority", 0)))
    return run_nodes(lambda ctx: [DriverNode(cfg, ctx)], ["driver"])


if __name__ == "__main__":
    sys.exit(main(sys.argv))
