"""A recorded teleoperation graph (``haptic-launch teleop_sim --record BAG``) as a
``TeleopResult``: the batch runner's arrays from the bag's topics, the session's config from the
parameters the recorder took from every node; ``metrics()`` and the figures are the batch run's.

Arrays (stamp k of both sides): ``master_q``, ``master_qd``, ``slave_q``: ``/master`` and
``/slave`` ``joint_states``; ``slave_command``: ``/slave/effort_command``; ``master_point``:
``/master/ee_pose`` mapped to the slave (``mapped_point``, from both sides' points at sample 0);
``slave_point``: ``/slave/ee_pose``; ``target``: ``/slave/pose_desired``; ``contact``, ``hand``:
``/slave`` and ``/master`` ``sim/hand_wrench``; ``estimate``: ``/slave/wrench_estimate``;
``sensor``: ``/slave/wrench_measured``; ``rendered``: ``/master/wrench_desired`` in slave units
(``rendered_force``); ``dissipated`` and ``silent``: the channel's messages ``/teleop/to_slave``
(the master's port) and ``/teleop/to_master`` (the slave's), joints ``energy`` and ``silent``.
A sample some topic lacks is left out, a stamp sent twice counts once, and samples beyond the
session's ``duration_s`` are left out. Why: docs/design/teleoperation.md.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.bag.bagfile import corrupt, listing, open_bag, topics_of
from haptic_dob.bag.cdr import command_label_stamp_ns, decode_vectors
from haptic_dob.bag.errors import BagError
from haptic_dob.bag.param_events import PARAMETER_EVENT, param_event
from haptic_dob.teleop.graph import NAMESPACES, SIDE_NODES, TO_MASTER, TO_SLAVE
from haptic_msgs_py.stamps import NS_PER_S, period_ns
from haptic_msgs_py.topics import PARAMETER_EVENTS
from haptic_msgs_py.wire import TYPESTORE
from haptic_sim.teleop.config import TeleopConfig
from haptic_sim.teleop.result import TeleopResult, mapped_point, rendered_force

#: stamped 3-vector topics read: the result's field -> topic
VECTORS = {
    "master_pose": "/master/ee_pose",
    "rendered": "/master/wrench_desired",
    "hand": "/master/sim/hand_wrench",
    "slave_point": "/slave/ee_pose",
    "target": "/slave/pose_desired",
    "contact": "/slave/sim/hand_wrench",
    "estimate": "/slave/wrench_estimate",
    "sensor": "/slave/wrench_measured",
}
JOINTS = {"master": "/master/joint_states", "slave": "/slave/joint_states"}
COMMAND = "/slave/effort_command"
LINKS = {"master": TO_SLAVE, "slave": TO_MASTER}  # each port's messages


@dataclass
class RecordedSession:
    """A teleoperation bag read back: the result and what was left out."""

    path: str
    result: TeleopResult
    samples_missing: int  # samples of 0..N-1 some topic lacks (left out)


def _first_of_each(stamps: np.ndarray, rows: np.ndarray) -> dict[int, np.ndarray]:
    """Stamp -> the first row with it."""
    out: dict[int, np.ndarray] = {}
    for s, row in zip(stamps.tolist(), rows, strict=True):
        out.setdefault(s, row)
    return out


def _joint_rows(datas: list[bytes]) -> dict[int, np.ndarray]:
    """Stamp -> rows (position, velocity, effort) of JointState messages."""
    out: dict[int, np.ndarray] = {}
    for data in datas:
        m: Any = TYPESTORE.deserialize_cdr(data, "sensor_msgs/msg/JointState")
        s = int(m.header.stamp.sec) * NS_PER_S + int(m.header.stamp.nanosec)
        if s not in out:
            n = len(m.position)
            vel = m.velocity if len(m.velocity) == n else np.full(n, np.nan)
            eff = m.effort if len(m.effort) == n else np.full(n, np.nan)
            out[s] = np.vstack((m.position, vel, eff))
    return out


def _command_rows(datas: list[bytes]) -> dict[int, np.ndarray]:
    """Stamp (its ``effort@`` label) -> the efforts of Float64MultiArray commands."""
    out: dict[int, np.ndarray] = {}
    for data in datas:
        s = command_label_stamp_ns(data)
        if s is not None and s not in out:
            m: Any = TYPESTORE.deserialize_cdr(data, "std_msgs/msg/Float64MultiArray")
            out[s] = np.asarray(m.data, dtype=np.float64)
    return out


def session_config(events: list[Any], shown: str) -> TeleopConfig:
    """The config of the recorded graph: each node's parameters as they were declared (its
    declaration events and the recorder's snapshot: ``new_parameters``), as its section."""
    sections: dict[str, dict[str, Any]] = {}
    for e in events:
        ns = e.node.rsplit("/", 1)[0].lstrip("/")
        if ns in NAMESPACES:
            declared = sections.setdefault(e.node, {})
            declared.update({k: v for k, v in e.values.items() if k in e.new})
    if any(v.get("clock_mode") == "realtime" for v in sections.values()):
        raise BagError(
            f"{shown}: a real-time recording (each side stamped by its own system clock): the "
            "two sides' samples cannot be paired by stamp; record the session in lockstep"
        )
    wanted = [f"/{ns}/{n}" for ns in NAMESPACES for n in SIDE_NODES[ns]]
    missing = [w for w in wanted if w not in sections]
    if missing:
        raise BagError(
            f"{shown} lacks the parameters of {', '.join(missing)} (a teleoperation graph "
            "recorded with haptic-launch --record has every node's)"
        )
    try:
        return TeleopConfig.from_sections(sections)
    except ValueError as exc:
        raise BagError(f"{shown}: the recorded parameters are not a session: {exc}") from None


def _read_topics(
    path: str | Path,
) -> tuple[dict[str, list[bytes]], dict[str, str], list[Any]]:
    """Each wanted topic's messages (raw), the bag's topics' types and the parameter events."""
    shown = str(path)
    wanted = {*VECTORS.values(), *JOINTS.values(), COMMAND, *LINKS.values()}
    with open_bag(path) as reader:
        topics = topics_of(reader)
        absent = sorted(wanted - set(topics))
        if absent:
            raise BagError(
                f"{shown} is not a recorded teleoperation graph: no {', '.join(absent)} "
                f"(topics: {listing(topics)})"
            )
        raw: dict[str, list[bytes]] = {t: [] for t in wanted}
        events: list[Any] = []
        conns = [c for c in reader.connections if c.topic in wanted or c.topic == PARAMETER_EVENTS]
        try:
            for conn, t, data in reader.messages(connections=conns):
                if conn.topic in raw:
                    raw[conn.topic].append(bytes(data))
                elif conn.msgtype == PARAMETER_EVENT:
                    events.append(param_event(reader.deserialize(data, conn.msgtype), t))
        except Exception as exc:  # a damaged chunk or record
            raise corrupt(shown, exc) from None
    events.sort(key=lambda e: e.time_ns)
    return raw, topics, events


def read_teleop_bag(path: str | Path) -> RecordedSession:
    """The session a teleoperation bag holds; ``BagError`` saying what is wrong with it."""
    shown = str(path)
    raw, types, events = _read_topics(path)
    config = session_config(events, shown)
    vec: dict[str, dict[int, np.ndarray]] = {}
    for name, topic in VECTORS.items():
        vec[name] = _first_of_each(*decode_vectors(raw[topic], types[topic], (0, 1, 2)))
    joints = {side: _joint_rows(raw[topic]) for side, topic in JOINTS.items()}
    links = {side: _joint_rows(raw[topic]) for side, topic in LINKS.items()}
    command = _command_rows(raw[COMMAND])
    tables: list[Mapping[int, Any]] = [*vec.values(), *joints.values(), *links.values(), command]
    period = period_ns(config.loop.rate_hz)
    n = config.loop.batch_cycles(None)
    stamps = [k * period for k in range(n) if all(k * period in t for t in tables)]
    if not stamps or stamps[0] != 0:
        raise BagError(f"{shown}: no sample 0 on every topic (nothing to analyse)")
    return RecordedSession(
        shown, _result(config, stamps, vec, joints, links, command), n - len(stamps)
    )


def _result(
    config: TeleopConfig,
    stamps: list[int],
    vec: dict[str, dict[int, np.ndarray]],
    joints: dict[str, dict[int, np.ndarray]],
    links: dict[str, dict[int, np.ndarray]],
    command: dict[int, np.ndarray],
) -> TeleopResult:
    """The arrays of ``stamps`` (each on every topic)."""
    t = config.teleop
    R = t.matrix
    period = period_ns(config.loop.rate_hz)
    dt = period * 1e-9  # as the batch runner's

    def stack(table: Mapping[int, np.ndarray]) -> np.ndarray:
        return np.array([table[s] for s in stamps])

    p_m0, p_s0 = vec["master_pose"][0], vec["slave_point"][0]
    master_js, slave_js = stack(joints["master"]), stack(joints["slave"])
    m_link, s_link = stack(links["master"]), stack(links["slave"])  # (n, 3, 5): pos, vel, eff
    e = 3  # the ``energy`` joint: position E_in, velocity E_out, effort dissipated
    return TeleopResult(
        config=config,
        t=np.array([s // period for s in stamps], dtype=np.float64) * dt,
        master_q=master_js[:, 0, 0],
        master_qd=master_js[:, 1, 0],
        slave_q=slave_js[:, 0, :],
        slave_command=stack(command),
        master_point=np.array(
            [mapped_point(R, t.position_scale, p_s0, p_m0, p) for p in stack(vec["master_pose"])]
        ),
        slave_point=stack(vec["slave_point"]),
        target=stack(vec["target"]),
        contact=stack(vec["contact"]),
        estimate=stack(vec["estimate"]),
        sensor=stack(vec["sensor"]),
        rendered=np.array([rendered_force(R, t.force_scale, f) for f in stack(vec["rendered"])]),
        hand=stack(vec["hand"]),
        e_in_master=m_link[:, 0, e],
        e_out_master=m_link[:, 1, e],
        e_in_slave=s_link[:, 0, e],
        e_out_slave=s_link[:, 1, e],
        dissipated=m_link[:, 2, e] + s_link[:, 2, e],
        silent=1.0 * m_link[:, 0, e + 1] + 2.0 * s_link[:, 0, e + 1],
    )
