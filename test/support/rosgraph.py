"""Helpers for tests that start ROS 2 processes: isolated domains, launched graphs, collectors.

Every multi-process test runs on its own random ``ROS_DOMAIN_ID`` with discovery limited to this
host, waits with timeouts only, and kills what it started by process group.
"""

from __future__ import annotations

import contextlib
import os
import random
import re
import signal
import struct
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterable, Iterator, Sequence
from pathlib import Path
from typing import Any

from support.waits import RESEND_S, answered, wait_until

BIN = Path(sys.executable).parent


def random_domain() -> int:
    """A random ROS domain id (``random_domains``); under pytest-xdist from this worker's share
    of the range, so that tests running at once never meet on one domain."""
    return random_domains(1)[0]


def random_domains(n: int) -> list[int]:
    """``n`` different random domain ids from this worker's share (``random_domain``): for graphs
    a test keeps up at once that must not meet (two draws of one id would join them).

    The range is 1-100, or ``HAPTIC_TEST_DOMAINS=LO-HI`` where two test runs share a machine."""
    lo, hi = (int(x) for x in os.environ.get("HAPTIC_TEST_DOMAINS", "1-100").split("-"))
    count = int(os.environ.get("PYTEST_XDIST_WORKER_COUNT", "1"))
    worker = int(os.environ.get("PYTEST_XDIST_WORKER", "gw0")[2:] or 0)
    span = (hi - lo + 1) // max(1, min(count, hi - lo + 1))
    start = lo + worker * span
    return random.sample(range(start, start + span), n)


def isolated_env(domain: int | None = None) -> dict[str, str]:
    """This environment with a random domain id (``random_domain``), localhost-only discovery,
    and the nodes' log lines written as they are said (unbuffered, whichever stream rcutils
    writes: a test whose evidence is a log line reads it while the process runs, and a
    ``RCUTILS_LOGGING_USE_STDOUT`` of the caller's would leave lines in a file's block buffer
    until the process ends, or lose them when it is killed)."""
    env = dict(os.environ)
    env["ROS_DOMAIN_ID"] = str(domain if domain is not None else random_domain())
    env["ROS_AUTOMATIC_DISCOVERY_RANGE"] = "LOCALHOST"
    env["RCUTILS_LOGGING_BUFFERED_STREAM"] = "0"
    env.pop("ROS_STATIC_PEERS", None)
    return env


@contextlib.contextmanager
def private_context(args: Sequence[str] = (), domain: str | None = None) -> Iterator[Any]:
    """An rclpy context of this process on ``domain`` (default: a random one; ``ROS_DOMAIN_ID``
    set while it lives, then put back), initialised with ``args``; shut down on the way out."""
    import rclpy  # lazy: tests that only start processes need no rclpy here
    from rclpy.context import Context  # lazy: as above

    saved = os.environ.get("ROS_DOMAIN_ID")
    os.environ["ROS_DOMAIN_ID"] = domain or str(random_domain())
    ctx = Context()
    try:
        rclpy.init(context=ctx, args=list(args))
        yield ctx
    finally:
        rclpy.try_shutdown(context=ctx)
        if saved is None:
            os.environ.pop("ROS_DOMAIN_ID", None)
        else:
            os.environ["ROS_DOMAIN_ID"] = saved


def alive(pid: int) -> bool:
    """Process ``pid`` runs: not gone, and not a zombie nobody reaped yet (an orphan's exit)."""
    try:
        with open(f"/proc/{pid}/stat") as f:
            return f.read().rsplit(")", 1)[1].split()[0] != "Z"
    except (FileNotFoundError, ProcessLookupError):
        return False


def descendants(pid: int) -> list[int]:
    """The processes ``pid`` started, and theirs, while they live (``/proc``'s children lists)."""
    found: list[int] = []
    todo = [pid]
    while todo:
        for children in Path(f"/proc/{todo.pop()}/task").glob("*/children"):
            with contextlib.suppress(OSError):
                kids = [int(x) for x in children.read_text().split()]
                found += kids
                todo += kids
    return found


class Process:
    """A child process in its own session, stopped with SIGINT then killed if it lingers."""

    def __init__(self, argv: list[str], env: dict[str, str], log: Path | None = None) -> None:
        self.log_path = log
        self._log = open(log, "w") if log else subprocess.DEVNULL  # noqa: SIM115
        self.proc = subprocess.Popen(
            argv, env=env, stdout=self._log, stderr=subprocess.STDOUT, start_new_session=True
        )

    def wait(self, timeout: float) -> int:
        """Wait for the exit code (raises ``subprocess.TimeoutExpired``)."""
        return self.proc.wait(timeout)

    def stop(self, timeout: float = 10.0) -> int | None:
        """SIGINT the process group, wait, then SIGKILL it and every process it started (a
        launch starts its nodes in sessions of their own: under SCHED_FIFO a stuck node can keep
        the launch itself from ever running, and would outlive the test)."""
        if self.proc.poll() is None:
            try:
                os.killpg(self.proc.pid, signal.SIGINT)
                self.proc.wait(timeout)
            except (subprocess.TimeoutExpired, ProcessLookupError):
                pass
        if self.proc.poll() is None:
            for pid in descendants(self.proc.pid):  # by id: what this process started
                with contextlib.suppress(ProcessLookupError):
                    os.kill(pid, signal.SIGKILL)
            with contextlib.suppress(ProcessLookupError):
                os.killpg(self.proc.pid, signal.SIGKILL)
            self.proc.wait(30)
        if self._log is not subprocess.DEVNULL:
            self._log.close()
        return self.proc.returncode

    def output(self) -> str:
        """What the process wrote so far (when logging to a file)."""
        return self.log_path.read_text() if self.log_path else ""


def resent(log: str) -> list[int]:
    """Stamps (ns) of the samples the device sent twice (its lockstep re-send after a timeout).

    A sample lost on a best-effort loop input stalls a lockstep run until the device sends it
    again (``lockstep_timeout_s``); it logs each re-send, so a test can tell them from duplicates.
    """
    found = re.findall(r"no effort_command for cycle (\d+) .*Sending the sample again", log)
    return [int(k) * 1_000_000 for k in found]


def launch(
    config: str,
    env: dict[str, str],
    sets: Iterable[str] = (),
    log: Path | None = None,
    extra: Iterable[str] = (),
) -> Process:
    """``haptic-launch CONFIG --set ...`` as a child process."""
    argv = [str(BIN / "haptic-launch"), config, *extra]
    for s in sets:
        argv += ["--set", s]
    return Process(argv, env, log)


class Collector:
    """An in-test node (private context) that records raw messages of some topics.

    ``records[topic]`` is a list of (receive time, CDR bytes); ``messages(topic)`` decodes them.
    Subscriptions are reliable, so a collector added to the device's ``wait_for`` sees every
    sample of a lockstep run. Storing bytes keeps it fast enough for several 2 kHz topics.

    A collector of the loop's topics reports its progress as a recorder does
    (``recorder/progress``, 50 times a second: the newest stamp received, minimum over its
    stamped topics still flowing; before the first sample, whether its readers have matched), so
    the device sends sample 0 only once it has matched and a lockstep device waits for it when a
    loaded machine leaves it behind, instead of running past the publishers' history
    (``back_pressure=False`` turns that off, e.g. for topics that stop while the loop goes on).
    ``best_effort=True`` subscribes to everything best effort, as a sensor-data reader does.
    """

    def __init__(
        self,
        env: dict[str, str],
        topics: dict[str, str],
        name: str = "collector",
        namespace: str = "",
        back_pressure: bool = True,
        best_effort: bool = False,
    ) -> None:
        import rclpy
        from rclpy.context import Context
        from rclpy.experimental import EventsExecutor

        from haptic_dob.bag.cdr import stamp_reader
        from haptic_dob.recorder.counts import RecordingCounts
        from haptic_msgs_py.ros.qos import CLOCK, RECORD
        from haptic_msgs_py.ros.raw import rclpy_type
        from haptic_msgs_py.topics import RECORDER_PROGRESS, SESSION_TOPICS

        self._saved = {
            k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")
        }
        os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = env["ROS_AUTOMATIC_DISCOVERY_RANGE"]
        self.context = Context()
        rclpy.init(context=self.context, args=[])
        # no parameter services: a recorder in the graph has nothing to ask this helper
        self.node = rclpy.create_node(
            name,
            namespace=namespace or None,
            context=self.context,
            start_parameter_services=False,
        )
        from rclpy.qos import QoSProfile, ReliabilityPolicy

        # loop topics: as the recorder takes them; others, such as /diagnostics, reliable
        volatile = QoSProfile(depth=100, reliability=ReliabilityPolicy.RELIABLE)
        self.topics = dict(topics)
        self.records: dict[str, list[tuple[float, bytes]]] = {t: [] for t in topics}
        self._lock = threading.Lock()
        self._subs: dict[str, Any] = {}
        self.counts = RecordingCounts()
        for topic, typename in topics.items():
            count = self.counts.add_topic(topic, typename)
            # the loop's topics carry the loop's stamps; others (/diagnostics) the node's clock
            loop_topic = topic.rsplit("/", 1)[-1] in SESSION_TOPICS
            read_stamp = stamp_reader(topic, typename) if loop_topic else None

            def cb(
                data: bytes, topic: str = topic, count: Any = count, read: Any = read_stamp
            ) -> None:
                with self._lock:
                    self.records[topic].append((time.monotonic(), data))
                    if read is not None:
                        count.wrote(read(data), 1_000_000)

            qos = RECORD if topic in SESSION_TOPICS else volatile
            if best_effort:  # as a sensor-data reader takes them (ext_observer_ros, say)
                qos = QoSProfile(depth=100, reliability=ReliabilityPolicy.BEST_EFFORT)
            self._subs[topic] = self.node.create_subscription(
                rclpy_type(typename), topic, cb, qos, raw=True
            )
        if back_pressure and any(t.rsplit("/", 1)[-1] in SESSION_TOPICS for t in topics):
            from std_msgs.msg import Header

            from haptic_dob.recorder.matching import ReaderMatch, reported_progress

            progress = self.node.create_publisher(Header, RECORDER_PROGRESS, CLOCK)
            count_publishers = self.node.count_publishers
            msg = Header(frame_id=self.node.get_fully_qualified_name())

            def report() -> None:
                readers = [
                    ReaderMatch(
                        s.topic_name, s.get_publisher_count(), count_publishers(s.topic_name)
                    )
                    for s in self._subs.values()
                ]
                with self._lock:
                    ns = reported_progress(self.counts.progress_ns(), self.counts, readers)
                msg.stamp.sec, msg.stamp.nanosec = divmod(ns, 1_000_000_000)
                progress.publish(msg)

            self.node.create_timer(0.02, report)
        # the events executor (as the nodes use): a loaded machine must not leave this test's
        # own subscriber more than the publishers' 2000-sample history behind
        self.executor = EventsExecutor(context=self.context)
        self.executor.add_node(self.node)
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._spin, daemon=True)
        self._thread.start()

    def _spin(self) -> None:
        while not self._stop.is_set() and self.context.ok():
            self.executor.spin_once(timeout_sec=0.05)

    def matched(self) -> bool:
        """Whether every subscription has matched a publisher (a volatile one gets nothing sent
        before)."""
        return all(sub.get_publisher_count() >= 1 for sub in self._subs.values())

    def count(self, topic: str) -> int:
        with self._lock:
            return len(self.records[topic])

    def wait_for(self, topic: str, n: int, timeout: float) -> bool:
        """Wait until ``n`` messages of ``topic`` arrived (False on timeout)."""
        return wait_until(lambda: self.count(topic) >= n, timeout, poll_s=0.02)

    def newest_stamp_ns(self, topic: str) -> int | None:
        """Header stamp (ns) of the last message of a Header-first ``topic`` (little-endian CDR)."""
        with self._lock:
            if not self.records[topic]:
                return None
            data = self.records[topic][-1][1]
        sec, nsec = struct.unpack_from("<iI", data, 4)
        return sec * 1_000_000_000 + nsec

    def wait_for_stamp(self, topic: str, stamp_ns: int, timeout: float) -> bool:
        """Wait until a message stamped ``stamp_ns`` or later arrived (False on timeout).

        Reliable readers get one writer's messages in order, so the newest tells.
        """

        def arrived() -> bool:
            newest = self.newest_stamp_ns(topic)
            return newest is not None and newest >= stamp_ns

        return wait_until(arrived, timeout, poll_s=0.02)

    def messages(self, topic: str) -> list[Any]:
        """The decoded (rosbags) messages of ``topic`` received so far."""
        from haptic_msgs_py.wire import decoder

        decode = decoder(self.topics[topic])
        with self._lock:
            raw = [m for _, m in self.records[topic]]
        return [decode(m) for m in raw]

    def decoded(self, topic: str) -> Callable[[], list[Any]]:
        """A function returning the decoded messages of ``topic`` received so far, each decoded
        once: for a poll (decoding every message on every poll grows with the run and, on a
        loaded machine, takes the CPU from the graph the test watches)."""
        from haptic_msgs_py.wire import decoder

        decode = decoder(self.topics[topic])
        done: list[Any] = []

        def messages() -> list[Any]:
            with self._lock:
                new = [m for _, m in self.records[topic][len(done) :]]
            done.extend(decode(m) for m in new)
            return list(done)

        return messages

    def close(self) -> None:
        import rclpy

        self._stop.set()
        self._thread.join(5)
        self.executor.shutdown()
        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        for k, v in self._saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def set_parameter(env: dict[str, str], node: str, name: str, value: Any, timeout: float = 10.0):
    """Call ``/<node>/set_parameters`` like ``ros2 param set``; returns (successful, reason)."""
    import rclpy
    from rclpy.context import Context
    from rclpy.parameter import Parameter

    saved = {k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")}
    os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
    os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = env["ROS_AUTOMATIC_DISCOVERY_RANGE"]
    ctx = Context()
    rclpy.init(context=ctx, args=[])
    try:
        from rcl_interfaces.srv import SetParameters

        n = rclpy.create_node(
            f"param_client_{random.randint(0, 10**6)}", context=ctx, start_parameter_services=False
        )
        cli = n.create_client(SetParameters, f"/{node.lstrip('/')}/set_parameters")
        if not cli.wait_for_service(timeout_sec=timeout):
            raise TimeoutError(f"/{node}/set_parameters did not appear within {timeout} s")
        req = SetParameters.Request(parameters=[Parameter(name, value=value).to_parameter_msg()])
        from rclpy.executors import SingleThreadedExecutor

        ex = SingleThreadedExecutor(context=ctx)
        ex.add_node(n)
        # asked again while no answer comes (a lost response; the same value set twice is the
        # same change, a refused one changes nothing either time)
        fut = answered(
            lambda: cli.call_async(req),
            timeout,
            step=lambda: ex.spin_once(timeout_sec=0.05),
            resend_s=min(RESEND_S, timeout / 2),
        )
        ex.shutdown()
        if not fut.done():
            raise TimeoutError(f"/{node}/set_parameters did not answer within {timeout} s")
        res = fut.result().results[0]
        n.destroy_node()
        return res.successful, res.reason
    finally:
        rclpy.try_shutdown(context=ctx)
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def start_nodes(
    config: Path,
    env: dict[str, str],
    sets: Iterable[str],
    log_dir: Path,
    namespace: str = "",
    groups: Iterable[Iterable[str]] = (),
) -> dict[str, Process]:
    """The nodes of ``config`` as processes via the ros2 run contract (no launcher, so a test
    can kill and restart one): each node alone, except ``groups`` (nodes sharing a process).

    Keyed by every node's name (the nodes of a group share one ``Process``).
    """
    from haptic_dob.launcher import parse_sets, plan, resolved_params, write_params_file

    params = resolved_params(config, parse_sets(list(sets)))
    params_file = write_params_file(params, log_dir)
    procs = {}
    for spec in plan(params, params_file, namespace, [list(g) for g in groups]):
        log = log_dir / f"{spec.name.replace(', ', '+')}.log"
        proc = Process([spec.executable, *spec.args], env, log)
        for node in spec.nodes:
            procs[node] = proc
    return procs


def stop_all(procs: dict[str, Process]) -> None:
    """Stop every process of ``start_nodes`` once (a group's appears under each of its nodes)."""
    for proc in {id(p): p for p in procs.values()}.values():
        proc.stop()


def restart(
    procs: dict[str, Process],
    name: str,
    env: dict[str, str],
    log_dir: Path,
    config: Path,
    sets: Iterable[str],
) -> None:
    """Start node ``name`` again with the same parameters."""
    from haptic_dob.launcher import parse_sets, plan, resolved_params, write_params_file

    params = resolved_params(config, parse_sets(list(sets)))
    params_file = write_params_file(params, log_dir)
    spec = next(s for s in plan(params, params_file, "") if s.name == name)
    procs[name] = Process([spec.executable, *spec.args], env, log_dir / f"{name}.restarted.log")


def switch(env: dict[str, str], mode: str, within: float = 30.0) -> tuple[bool, str]:
    """Set the controller's mode; retried while refused because the input is not flowing yet.

    In OL the observer is off the lockstep critical path: on a loaded machine it may lag more than
    the controller's warm window, and the switch is then refused (as designed) until it catches up.
    A set that got no answer at all (``set_parameter`` asks again within its timeout) is tried
    again too.
    """
    answer: tuple[bool, str] = (False, "no answer")

    def accepted() -> bool:
        nonlocal answer
        try:
            answer = set_parameter(env, "controller_node", "mode", mode)
        except TimeoutError as exc:
            answer = (False, str(exc))
            return False
        return answer[0] or "not flowing" not in answer[1]

    wait_until(accepted, within, poll_s=0.5)
    return answer


def read_force(msg: Any) -> tuple[float, float, float]:
    """Force (N) of a WrenchStamped (rclpy or rosbags message)."""
    f = msg.wrench.force
    return (f.x, f.y, f.z)
