"""A recording killed before it closed (kill -9, a crash, a power cut) keeps all but its last
second: the recorder makes what it wrote durable at least once a second, and ``haptic-record
--recover`` writes the complete part to a new bag that every tool opens."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pytest

from haptic_dob.bag.errors import BagError
from haptic_dob.bag.reader import open_bag
from haptic_dob.bag.recover import complete_mcap_prefix, recover
from haptic_dob.bag.write import make_durable, open_writer
from haptic_msgs_py import wire
from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from haptic_msgs_py.wire import TYPESTORE
from support.paths import tool

JS_TYPE = SESSION_TOPICS[JOINT_STATES]
PERIOD_NS = 1_000_000  # 1 kHz


def sample(k: int) -> bytes:
    """Joint state k (stamp k ms) as CDR bytes."""
    msg = wire.joint_state(["slide"], "base_link")
    msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(k * PERIOD_NS, 10**9)
    msg.position = np.array([1e-6 * k])
    msg.velocity = np.zeros(1)
    msg.effort = np.zeros(1)
    return wire.encode(msg)


def killed_copy(
    bag: Path, storage: str, durable_at: tuple[int, ...], n: int, to: Path, late: bool = False
) -> None:
    """Write ``n`` samples to a new bag, durable after each sample count in ``durable_at``, then
    copy the files as they are on disk without closing the writer: what a kill -9 leaves.

    ``late``: each sample also on ``/late``, written after the next sample of ``/joint_states``
    and logged at its own stamp, as the recorder logs a loop message that came late: the log
    times go back in the file."""
    writer = open_writer(bag, storage)
    conn = writer.add_connection("/joint_states", JS_TYPE, typestore=TYPESTORE)
    other = writer.add_connection("/late", JS_TYPE, typestore=TYPESTORE) if late else None
    for k in range(n):
        writer.write(conn, k * PERIOD_NS, sample(k))
        if other is not None and k > 0:
            writer.write(other, (k - 1) * PERIOD_NS, sample(k - 1))
        if k + 1 in durable_at:
            make_durable(writer)
    to.mkdir()
    for f in bag.iterdir():
        if f.name != "metadata.yaml":
            shutil.copy2(f, to / f.name)
    writer.close()


def stamps_of(bag: Path, topic: str = "/joint_states") -> list[int]:
    """The joint-state stamps (ns) of a closed bag, through the analysis' own reader."""
    with open_bag(bag) as reader:
        conns = [c for c in reader.connections if c.topic == topic]
        return [
            stamp_ns(TYPESTORE.deserialize_cdr(d, JS_TYPE)) for _, _, d in reader.messages(conns)
        ]


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_everything_made_durable_is_recovered(tmp_path: Path, storage: str) -> None:
    killed = tmp_path / "killed"
    killed_copy(tmp_path / "live", storage, (1000, 2000), 2500, killed)
    with pytest.raises(BagError, match=r"no metadata\.yaml"), open_bag(killed):
        pass
    got = recover(killed)
    assert got.out == tmp_path / "killed_recovered"
    assert (got.messages, got.topics, got.storage) == (2000, 1, storage)
    assert stamps_of(got.out) == [k * PERIOD_NS for k in range(2000)]


@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_log_times_that_go_back_are_recovered(tmp_path: Path, storage: str) -> None:
    killed = tmp_path / "killed"
    killed_copy(tmp_path / "live", storage, (1000, 2000), 2500, killed, late=True)
    got = recover(killed)
    assert got.messages == 2000 + 1999
    assert stamps_of(got.out) == [k * PERIOD_NS for k in range(2000)]
    assert stamps_of(got.out, "/late") == [k * PERIOD_NS for k in range(1999)]


def test_a_record_cut_in_the_middle_is_left_out(tmp_path: Path) -> None:
    killed = tmp_path / "killed"
    killed_copy(tmp_path / "live", "mcap", (1000, 2000), 2000, killed)
    (mcap,) = killed.glob("*.mcap")
    data = mcap.read_bytes()
    # the second chunk's tail and its message index (16 bytes a message) never reached the disk
    cut = data[: -(16 * 1000 + 4000)]
    mcap.write_bytes(cut)
    assert complete_mcap_prefix(cut) < len(cut)
    got = recover(killed, tmp_path / "out")
    assert got.messages == 1000 and got.dropped_bytes > 0
    assert stamps_of(tmp_path / "out") == [k * PERIOD_NS for k in range(1000)]


def test_refusals_are_one_line(tmp_path: Path) -> None:
    closed = tmp_path / "closed"
    writer = open_writer(closed, "mcap")
    writer.add_connection("/joint_states", JS_TYPE, typestore=TYPESTORE)
    writer.close()
    empty = tmp_path / "empty"
    empty.mkdir()
    early = tmp_path / "early"
    killed_copy(tmp_path / "live", "sqlite3", (), 10, early)  # nothing committed yet
    cases = {
        closed: "it was closed, there is nothing to recover",
        empty: "holds no .mcap or .db3 file",
        tmp_path / "missing": "no such file or directory",
        early: "no complete topic record",
    }
    for bag, reason in cases.items():
        out = subprocess.run(
            [tool("haptic-record"), "--recover", str(bag)], capture_output=True, text=True
        )
        assert out.returncode == 2, out
        assert out.stderr.count("\n") == 1 and reason in out.stderr, out.stderr
    killed = tmp_path / "killed"
    killed_copy(tmp_path / "live2", "mcap", (1000,), 1200, killed)
    assert recover(killed).messages == 1000
    with pytest.raises(BagError, match="exists; give another output path"):
        recover(killed)


@pytest.mark.multiprocess
@pytest.mark.slow
@pytest.mark.parametrize("storage", ["mcap", "sqlite3"])
def test_recorder_killed_at_1khz_loses_at_most_its_last_second(
    tmp_path: Path, storage: str
) -> None:
    """A 1 kHz stream into ``haptic-record``; kill -9 once the recorder has written the 3000th
    sample and then one sent more than its one-second durability interval later (its progress
    reports say what it wrote): every sample up to the 3000th is in the recovered bag, without a
    gap. Bounded in what the recorder wrote, not in seconds: a busy machine leaves it behind.
    The stream never runs more than half the publisher's history ahead of what the recorder wrote:
    a recorder left further behind than the publisher's history loses samples (and reports them
    missing), which is its capacity, not its durability."""
    from haptic_dob.bag.cdr import header_stamp_ns
    from haptic_dob.recorder.recording import DURABLE_EVERY_NS
    from haptic_msgs_py.ros import qos
    from haptic_msgs_py.ros.raw import RawPublisher
    from haptic_msgs_py.topics import RECORDER_PROGRESS
    from support.rosgraph import Collector, Process, isolated_env
    from support.waits import wait_until

    env = isolated_env()
    bag = tmp_path / "session"
    col = Collector(env, {RECORDER_PROGRESS: "std_msgs/msg/Header"})
    pub = RawPublisher(col.node, JS_TYPE, JOINT_STATES, qos.LOOP)
    rec = Process(
        [tool("haptic-record"), str(bag), "--storage", storage, "--topic", JOINT_STATES],
        env,
        tmp_path / "record.log",
    )
    msg = wire.joint_state(["slide"], "base_link")
    msg.velocity, msg.effort = np.zeros(1), np.zeros(1)

    def written_ns() -> int:
        """The newest stamp the recorder reported written (ns; -1 before any report)."""
        with col._lock:
            reports = col.records[RECORDER_PROGRESS]
            return header_stamp_ns(reports[-1][1]) if reports else -1  # type: ignore[return-value]

    kept = 2999 * PERIOD_NS  # the 3000th sample
    lead = qos.LOOP_HISTORY // 2  # samples the stream may run ahead of what the recorder wrote
    kept_at = later = None  # when it was written; the first sample sent a durability interval on
    try:
        assert wait_until(lambda: pub.get_subscription_count() >= 1, 60), rec.output()
        start = time.monotonic()
        for k in range(60_000):
            while (k - lead) * PERIOD_NS > written_ns():  # back-pressure, as a lockstep device
                if time.monotonic() - start > 120:
                    pytest.fail(f"the recorder wrote up to {written_ns()} ns in 120 s")
                time.sleep(0.001)
            msg.header.stamp.sec, msg.header.stamp.nanosec = divmod(k * PERIOD_NS, 10**9)
            msg.position = np.array([1e-6 * k])
            pub.publish(msg)
            now = time.monotonic()
            if kept_at is None and written_ns() >= kept:
                kept_at = now
            elif kept_at is not None and later is None and now > kept_at + DURABLE_EVERY_NS * 1e-9:
                later = k
            if later is not None and written_ns() >= later * PERIOD_NS:
                break
            ahead = start + (k + 1) * 1e-3 - time.monotonic()  # paced at 1 kHz
            if ahead > 0:
                time.sleep(ahead)
        else:
            pytest.fail(f"the recorder wrote up to {written_ns()} ns of 60 s sent")
        os.killpg(rec.proc.pid, signal.SIGKILL)
        rec.proc.wait(10)
    finally:
        rec.stop()
        col.close()
    assert not (bag / "metadata.yaml").exists()
    out = subprocess.run(
        [tool("haptic-record"), "--recover", str(bag)], capture_output=True, text=True
    )
    assert out.returncode == 0, out.stderr
    stamps = stamps_of(tmp_path / "session_recovered")
    assert len(stamps) >= 3000, (len(stamps), out.stdout, rec.output()[-2000:])
    assert stamps == [k * PERIOD_NS for k in range(len(stamps))]
