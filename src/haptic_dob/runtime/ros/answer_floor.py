"""The on-time floor: the share of states any rclpy loop of a given cost answers in time here.

A driver-like process publishes a Force Dimension-sized ``JointState`` (raw) at each instant of
its rate, under the scheduling the loop is given, skipping the periods it overran as a controller
manager does; an answering process, as the bridge, takes it with an events executor, burns
``before_us`` of Python, answers, then burns ``after_us``. An answer is on time when DDS
received it in the driver's process before the next instant: the bridge benchmark's criterion
(``haptic_msgs_py.ros.inbox``). With no work it is the raw answer's floor, the on-time
counterpart of one raw hop; with a cycle's CPU, the share a loop of that cost gets here now.
Both sides use the loop's QoS (``dds_hop``); the work is pure Python, calibrated at the
process's start (its median speed), so it slows down with the machine as the loop's code does.
"""

from __future__ import annotations

import os
import random
import statistics
import struct
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

import numpy as np

from haptic_dob.runtime.cpu_latency import hold
from haptic_dob.runtime.ros.dds_hop import Peer, peer_node, run_peers
from haptic_msgs_py import wire

FLOOR_S = 10.0  # length of one run (s), as a bridge benchmark's session
WARM_UP = 0.05  # share of the states left out at the start
_SEQ = struct.Struct("<i")  # the state's stamp.sec carries its index (after the CDR header)
_SEQ_AT = 4


@dataclass(frozen=True)
class AnswerFloor:
    """One run: states answered before the next instant, answered at all (%), the answer's
    latency from the state's send (us, p50 and p99), and the states counted (sent, less the
    warm-up)."""

    on_time_pct: float
    answered_pct: float
    latency_p50_us: float
    latency_p99_us: float
    states: int


def burner(us: float) -> Callable[[], None]:
    """A pure-Python loop that takes about ``us`` at this process's median speed."""

    def spin(m: int) -> float:
        s = 0.0
        for i in range(m):
            s += i * 0.5
        return s

    if us <= 0.0:
        return lambda: None
    runs = []
    for _ in range(200):
        t = time.perf_counter()
        spin(1000)
        runs.append(time.perf_counter() - t)
    steps = max(1, round(us * 1e-6 / (statistics.median(runs) / 1000)))

    def run() -> None:
        spin(steps)

    return run


def _scheduled(priority: int | None, latency: int | None, cpus: set[int] | None) -> int | None:
    """SCHED_FIFO ``priority``, a PM QoS hold of ``latency`` us and the CPUs ``cpus`` where
    asked (the hold's descriptor, or None)."""
    if cpus:
        os.sched_setaffinity(0, cpus)
    if priority:
        os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
    return None if latency is None else hold(latency)


def check_sched(priority: int | None, latency: int | None) -> None:
    """``ValueError`` with the reason when this process may not have SCHED_FIFO ``priority`` or
    hold a PM QoS ``latency`` (us); asked once here, not in each measuring process."""
    if priority:
        before = os.sched_getscheduler(0), os.sched_getparam(0)
        try:
            os.sched_setscheduler(0, os.SCHED_FIFO, os.sched_param(priority))
        except (OSError, ValueError) as exc:
            raise ValueError(f"SCHED_FIFO priority {priority} refused ({exc})") from None
        os.sched_setscheduler(0, *before)
    if latency is not None:
        os.close(hold(latency))


def _answerer(domain: str, before_us: float, after_us: float, seconds: float, sched: Any) -> None:
    """The loop's side: each state in, ``before_us`` of work, its answer out, ``after_us``."""
    _held = _scheduled(*sched)  # the PM QoS request lasts while it is open
    ctx, node, ex = peer_node("floor_loop", domain)
    # lazy: only the peer processes load rclpy
    from sensor_msgs.msg import JointState

    from haptic_msgs_py.ros.qos import LOOP, LOOP_IN_BEST_EFFORT

    pub = node.create_publisher(JointState, "floor_answer", LOOP)
    before, after = burner(before_us), burner(after_us)

    def on_state(data: bytes) -> None:
        before()
        pub.publish(data)  # the state's bytes back: its index travels with it
        after()

    node.create_subscription(JointState, "floor_state", on_state, LOOP_IN_BEST_EFFORT, raw=True)
    ex.add_node(node)
    end = time.monotonic() + seconds + 60.0
    while time.monotonic() < end and ctx.ok():
        ex.spin_once(timeout_sec=0.05)


def _driver(domain: str, rate_hz: float, seconds: float, sched: Any, out: Any) -> None:
    """The driver's side: a state at each instant; the answers read as a ros2_control update
    reads its commands, by DDS's reception time (system clock), from a subscription no executor
    spins (``Inbox``, as the test drivers), so the driver's own wake-ups do not count."""
    _held = _scheduled(*sched)  # the PM QoS request lasts while it is open
    _ctx, node, _ex = peer_node("floor_driver", domain)
    # lazy: only the peer processes load rclpy
    from sensor_msgs.msg import JointState

    from haptic_msgs_py.ros.inbox import Inbox
    from haptic_msgs_py.ros.qos import LOOP, LOOP_IN_BEST_EFFORT

    msg = wire.joint_state(["fd_x", "fd_y", "fd_z"])
    msg.position = msg.velocity = msg.effort = np.array([0.01, -0.02, 0.03])
    state = bytearray(wire.encode(msg))
    pub = node.create_publisher(JointState, "floor_state", LOOP)
    inbox = Inbox(node, "sensor_msgs/msg/JointState", "floor_answer", LOOP_IN_BEST_EFFORT)
    got: dict[int, int] = {}  # state index -> its first answer's reception (system ns)

    def take() -> None:
        for received_ns, data in inbox.take():
            got.setdefault(_SEQ.unpack_from(data, _SEQ_AT)[0], received_ns)

    end = time.monotonic() + 30.0
    while pub.get_subscription_count() < 1 or not node.count_publishers("floor_answer"):
        if time.monotonic() > end:
            return
        time.sleep(0.01)
    period = round(1e9 / rate_hz)
    t0 = time.monotonic_ns() + 500_000_000  # a margin for the answerer's side to match too
    sent: dict[int, int] = {}  # state index -> its send (system ns)
    k, n = 0, int(seconds * rate_hz)
    while k < n:
        due = t0 + k * period
        while (left := due - time.monotonic_ns()) > 0:
            time.sleep(left * 1e-9)
        late = time.monotonic_ns() - due
        if late > period:  # overran: on to the grid's next instant, as a controller manager
            k += late // period
            continue
        take()
        _SEQ.pack_into(state, _SEQ_AT, k)
        sent[k] = time.time_ns()
        pub.publish(bytes(state))
        k += 1
    time.sleep(0.2)
    take()
    t0_system = t0 + time.time_ns() - time.monotonic_ns()
    out.put(count(sent, got, t0_system, period))


def count(sent: dict[int, int], got: dict[int, int], t0_ns: int, period_ns: int) -> AnswerFloor:
    """The figures of a run: ``sent`` and ``got`` map a state's index to its send and its first
    answer's reception (ns, one clock), ``t0_ns`` is instant 0 on that clock; the first
    ``WARM_UP`` of the states sent are left out. ``RuntimeError`` when nothing was sent or
    answered."""
    kept = sorted(sent)[int(len(sent) * WARM_UP) :]
    if not kept:
        raise RuntimeError("the answer floor's driver sent no state")
    on_time = sum(1 for k in kept if k in got and got[k] < t0_ns + (k + 1) * period_ns)
    latency = sorted(got[k] - sent[k] for k in kept if k in got)
    if not latency:
        raise RuntimeError("the answer floor's states got no answer")
    return AnswerFloor(
        on_time_pct=100.0 * on_time / len(kept),
        answered_pct=100.0 * len(latency) / len(kept),
        latency_p50_us=latency[len(latency) // 2] * 1e-3,
        latency_p99_us=latency[int(0.99 * (len(latency) - 1))] * 1e-3,
        states=len(kept),
    )


def answer_floor(
    rate_hz: float,
    seconds: float = FLOOR_S,
    work_us: tuple[float, float] = (0.0, 0.0),
    sched: tuple[int | None, int | None] = (None, None),
    domain_id: int | None = None,
    cpus: set[int] | None = None,
) -> AnswerFloor:
    """One run at ``rate_hz`` for ``seconds``, the answerer's work ``work_us`` (before, after),
    both sides under ``sched`` (SCHED_FIFO priority, PM QoS latency us; None: not asked) on
    ``cpus`` (None: this process's), on ``domain_id`` (None: a random one of 101-200)."""
    check_sched(*sched)
    domain = str(random.randint(101, 200) if domain_id is None else domain_id)
    driver: Peer = (_driver, (domain, rate_hz, seconds, (*sched, cpus)))
    answerer: Peer = (_answerer, (domain, *work_us, seconds, (*sched, cpus)))
    floor: AnswerFloor = run_peers(driver, answerer, seconds + 90.0, "the answer floor")
    return floor
