"""The recorder with the node graph: lossless lockstep recordings, signals, a live mode switch."""

from __future__ import annotations

import os
import signal
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.bag import analyze_bag, read_bag
from haptic_dob.bag.cdr import command_label_stamp_ns
from haptic_dob.bag.reader import open_bag
from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_msgs_py.stamps import NS_PER_S
from haptic_msgs_py.topics import RECORDER_PROGRESS
from haptic_sim.slide.session import SessionConfig, run_session
from support.paths import tool
from support.recorded import (
    assert_logged_on_session_time,
    assert_received_written_in_bag,
    bag_stamps,
)
from support.rosgraph import Collector, Process, isolated_env, launch, resent, switch
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

LOOP = ["environment_node", "observer_node", "controller_node"]
DEVICE_TOPICS = ["/joint_states", "/ee_pose", "/ee_twist", "/wrench_measured", "/sim/hand_wrench"]
ANSWER_TOPICS = ["/wrench_desired", "/wrench_estimate", "/effort_estimate", "/effort_command"]
MS = 1_000_000


def wait_for(nodes: list[str]) -> str:
    return f"device_node:wait_for=[{', '.join(LOOP + nodes)}]"


def assert_device_topics(
    stamps: dict[str, np.ndarray], resends: list[int], last: int | None
) -> None:
    """Each device sample once from 0 (to ``last``), plus exactly the re-sent ones again.

    Sample 0 may come several times: the device repeats it until command 0 arrives.
    """
    for topic in DEVICE_TOPICS:
        s = stamps[topic]
        unique, counts = np.unique(s, return_counts=True)
        n = unique.size if last is None else last // MS + 1
        assert np.array_equal(unique, np.arange(n) * MS), topic
        unique, counts = unique[1:], counts[1:]
        twice = sorted(unique[counts > 1].tolist())
        assert counts.max() <= 2 and twice == sorted(r for r in resends if r <= unique[-1]), topic


def test_recorded_lockstep_session_loses_nothing_and_equals_the_batch_run(root, tmp_path) -> None:
    """30 s at 1 kHz, DOB Kf=1: an MCAP (launched recorder) and a sqlite3 (haptic-record) bag.

    Every device topic holds samples 0..N once each, plus the samples the device re-sent (it logs
    each): exactly what it published. Every answer topic holds the cycles 0..N-1; what each
    recorder received it wrote; both bags analyse to the batch run's ``summary()`` exactly.
    """
    seconds = 30.0  # 30 000 cycles into two bags: 96 s of the suite here (60 s took 164 s)
    n = round(seconds * 1000)
    env = isolated_env()
    mcap, sqlite = tmp_path / "mcap", tmp_path / "sqlite"
    rec = Process(
        [tool("haptic-record"), str(sqlite), "--storage", "sqlite3", "--node-name", "rec_sql"],
        env,
        tmp_path / "record.log",
    )
    sets = [
        wait_for(["recorder_node", "rec_sql"]),
        f"device_node:duration_s={seconds}",
        "controller_node:mode=DOB",
        "controller_node:kf=1.0",
        f"recorder_node:output={mcap}",
    ]
    graph = launch(str(root / "config" / "slide_sim.yaml"), env, sets, tmp_path / "launch.log")
    try:
        assert graph.wait(300) == 0, graph.output()
        assert rec.stop(30) == 0, rec.output()
    finally:
        graph.stop()
        rec.stop()
    resends = resent(graph.output())
    assert "lost its input" not in graph.output()  # no fallback: the run is the batch run
    assert f"bag: {sqlite} (sqlite3)" in rec.output()
    cfg = SessionConfig.from_yaml(root / "config" / "slide_sim.yaml").replace(
        law=ImpedanceLaw(ControlMode.DOB, 1.0, 4.0), loop__duration_s=seconds
    )
    res = run_session(cfg)
    want = res.summary()
    for bag in (mcap, sqlite):
        stamps = bag_stamps(bag)
        assert_device_topics(stamps, resends, n * MS)
        for topic in ANSWER_TOPICS:
            unique = np.unique(stamps[topic])
            assert np.array_equal(unique[:n], np.arange(n) * MS), (bag, topic)
        report = assert_received_written_in_bag(bag)
        assert report["parameter_snapshots"] >= 4  # device, environment, observer, controller
        assert_logged_on_session_time(bag)
        assert all(c["gaps"] == 0 for c in report["topics"].values())
        data = read_bag(bag)
        assert np.array_equal(data.motion.values[:n], res.q)
        assert np.array_equal(data.force.values[:n], res.force_measured)
        (seg,) = analyze_bag(bag).segments
        got = seg.as_dict()
        for key in (
            "bandwidth_hz",
            "impedance_error_pct",
            "coherence_in_band",
            "controller",
            "kf",
            "stiffness_n_per_m",
            "observer_gain",
        ):
            assert got[key] == getattr(want, key), (bag, key)


def switch_stamp(path: Path, kf: float) -> int:
    """Stamp (ns) of the first command computed by the DOB law (from the recorded signals)."""
    from support.rosgraph import read_force

    by: dict[str, dict[int, float]] = {"/wrench_desired": {}, "/wrench_estimate": {}}
    cmds: list[tuple[int, float]] = []
    with open_bag(path) as reader:
        for conn, _, data in reader.messages():
            if conn.topic in by:
                m = reader.deserialize(data, conn.msgtype)
                by[conn.topic][m.header.stamp.sec * NS_PER_S + m.header.stamp.nanosec] = read_force(
                    m
                )[0]
            elif conn.topic == "/effort_command":
                m = reader.deserialize(data, conn.msgtype)
                stamp = command_label_stamp_ns(data)
                assert stamp is not None, "a command without its cycle label"
                cmds.append((stamp, float(m.data[0])))
    first = None
    for k, u in sorted(cmds):
        if k not in by["/wrench_estimate"]:
            continue  # the observer missed this sample (best-effort input): OL needs none
        fw, fe = by["/wrench_desired"][k], by["/wrench_estimate"][k]
        ol, dob = np.clip(fw, -4, 4), np.clip(fw + kf * (fw + fe), -4, 4)
        if abs(u - dob) < 1e-12 and abs(u - ol) > 1e-12:
            first = k if first is None else first
        elif abs(u - ol) < 1e-12 and abs(u - dob) > 1e-12:
            assert first is None, "an OL command after the switch"
    assert first is not None, "no DOB command recorded"
    return first


def test_signals_leave_readable_bags_and_a_live_switch_splits_the_session(root, tmp_path) -> None:
    """Three recorders on one lockstep run: SIGTERM and SIGINT mid-session, one to the end."""
    env = isolated_env()
    a, b, c = tmp_path / "a", tmp_path / "b_term", tmp_path / "c_int"
    rec_b = Process(
        [tool("haptic-record"), str(b), "--storage", "sqlite3", "--node-name", "rec_b"],
        env,
        tmp_path / "b.log",
    )
    rec_c = Process(
        [tool("haptic-record"), str(c), "--node-name", "rec_c"], env, tmp_path / "c.log"
    )
    col = Collector(env, {RECORDER_PROGRESS: "std_msgs/msg/Header"})
    sets = [
        wait_for(["recorder_node", "rec_b", "rec_c", "collector"]),
        "device_node:duration_s=0.0",
        "controller_node:kf=1.0",
        f"recorder_node:output={a}",
    ]
    graph = launch(str(root / "config" / "slide_sim.yaml"), env, sets, tmp_path / "launch.log")

    progress_msgs = col.decoded(RECORDER_PROGRESS)

    def progress() -> float:
        msgs = progress_msgs()
        return max((m.stamp.sec + m.stamp.nanosec * 1e-9 for m in msgs), default=0.0)

    def reach(seconds: float, timeout: float) -> None:
        assert wait_until(lambda: progress() >= seconds, timeout), (
            f"the session did not reach {seconds} s\n" + graph.output()
        )

    try:
        reach(6.0, 120)
        ok, reason = switch(env, "DOB")  # retried while the observer catches up
        assert ok, reason
        # the device runs at most max_recorder_lag_s (0.5 s) ahead of the recorders' progress
        t_switched = progress() + 1.0  # simulated s: the switch's stamp is before this
        reach(t_switched + 5.0, 60)
        os.killpg(rec_b.proc.pid, signal.SIGTERM)
        os.killpg(rec_c.proc.pid, signal.SIGINT)
        assert rec_b.wait(30) == 0, rec_b.output()
        assert rec_c.wait(30) == 0, rec_c.output()
        reach(t_switched + 8.0, 60)
    finally:
        graph.stop()
        col.close()
        rec_b.stop()
        rec_c.stop()
    resends = resent(graph.output())
    for bag, proc, storage in ((b, rec_b, "sqlite3"), (c, rec_c, "mcap")):
        assert f"bag: {bag} ({storage})" in proc.output()
        assert_received_written_in_bag(bag)
        assert_logged_on_session_time(bag)
        stamps = bag_stamps(bag)
        assert stamps["/ee_pose"].size > 10_000
        assert_device_topics(stamps, resends, None)  # from sample 0 on, none missing
    assert_received_written_in_bag(a)
    analysis = analyze_bag(a)
    segs = analysis.segments
    assert [s.controller for s in segs] == ["OL", "DOB"]
    assert [s.kf for s in segs] == [1.0, 1.0]
    assert all(s.figures.transparency is not None for s in segs)
    k_switch = switch_stamp(a, 1.0)
    boundary = round(segs[1].start_s * NS_PER_S)
    assert 6.0 * NS_PER_S <= k_switch <= t_switched * NS_PER_S
    assert abs(boundary - k_switch) <= 5 * MS, (boundary, k_switch)
