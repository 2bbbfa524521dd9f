"""haptic-launch: the graph from one config, Ctrl-C forwarding, composition, bad input."""

from __future__ import annotations

import contextlib
import os
import re
import signal
import subprocess
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np
import pytest

from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from haptic_sim.slide.session import SessionConfig, run_session
from support.paths import can_request_cpu_latency, tool
from support.rosgraph import Collector, Process, alive, isolated_env, launch
from support.waits import wait_until

#: executable (as in a node's command line) -> node name
NODE_NAMES = {
    "haptic-device-node": "device_node",
    "haptic-environment-node": "environment_node",
    "haptic-observer-node": "observer_node",
    "haptic-controller-node": "controller_node",
}


def children_of(pid: int) -> list[int]:
    """PIDs whose parent is ``pid``."""
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True)
    return [int(p) for p in out.stdout.split()]


def running(graph: Process, log: Path) -> Callable[[], None]:
    """A ``check`` for ``wait_until``: fails the test, with the log, once ``graph`` has ended."""

    def check() -> None:
        assert graph.proc.poll() is None, log.read_text()

    return check


@pytest.mark.multiprocess
@pytest.mark.parametrize(
    ("sig", "extra", "processes"),
    [
        (signal.SIGINT, [], 1),
        (signal.SIGTERM, ["--processes"], 4),
        (signal.SIGHUP, [], 1),
        (signal.SIGKILL, ["--processes"], 4),
    ],
    ids=["SIGINT-composed", "SIGTERM-processes", "SIGHUP-composed", "SIGKILL-processes"],
)
def test_signal_to_the_launcher_stops_every_node_cleanly(
    root, tmp_path, sig, extra: list[str], processes: int
) -> None:
    """The loop composed in one process (the default) or each node in its own: a signal to the
    launcher stops every one cleanly, a closed terminal's SIGHUP too; a kill -9 of the launcher
    leaves each node SIGTERM (its parent-death signal), so each still stops cleanly."""
    env = isolated_env()
    log = tmp_path / "launch.log"
    out = open(log, "w")  # noqa: SIM115 - closed in finally, the launcher writes to it
    proc = subprocess.Popen(
        [
            tool("haptic-launch"),
            str(root / "config" / "slide_sim.yaml"),
            *extra,
            "--set",
            "device_node:clock_mode=realtime",
            "--set",
            "device_node:duration_s=0.0",
        ],
        env=env,
        stdout=out,
        stderr=subprocess.STDOUT,
    )
    kids: list[int] = []

    def started() -> list[int]:
        found = children_of(proc.pid)
        return found if len(found) >= processes else []

    try:
        kids = wait_until(started, 30, poll_s=0.2)
        assert len(kids) == processes, log.read_text()
        time.sleep(2.0)  # let the loop run
        proc.send_signal(sig)
        assert proc.wait(30) == (-sig if sig == signal.SIGKILL else 0), log.read_text()
        for pid in kids:  # orphans after a kill -9: they stop on their own
            assert wait_until(lambda p=pid: not alive(p), 30), f"node {pid} survived the launcher"
        text = log.read_text()
        assert "Traceback" not in text and "did not stop" not in text, text
    finally:
        leftover = children_of(proc.pid) if proc.poll() is None else []  # before they are orphans
        if proc.poll() is None:
            proc.kill()
        for pid in leftover + [p for p in kids if alive(p)]:
            with contextlib.suppress(ProcessLookupError):
                os.kill(pid, signal.SIGKILL)
        out.close()


@pytest.mark.multiprocess
@pytest.mark.slow
def test_composed_graph_reproduces_the_batch_run(root, tmp_path) -> None:
    """All nodes in one process under one executor: the same trajectory as the batch run."""
    env = isolated_env()
    col = Collector(env, {JOINT_STATES: SESSION_TOPICS[JOINT_STATES]})
    graph = launch(
        str(root / "config" / "slide_sim.yaml"),
        env,
        [
            "device_node:wait_for=[environment_node, observer_node, controller_node, collector]",
            "device_node:duration_s=2.0",
            "controller_node:mode=DOB",
            "controller_node:kf=1.0",
        ],
        tmp_path / "launch.log",
        extra=["--composed"],
    )
    try:
        assert graph.wait(120) == 0, graph.output()
        assert col.wait_for(JOINT_STATES, 2001, 10)
    finally:
        graph.stop()
        col.close()
    q = np.array([m.position[0] for m in col.messages(JOINT_STATES)])
    cfg = SessionConfig.from_yaml(root / "config" / "slide_sim.yaml").replace(
        loop__duration_s=2.0, law__mode="DOB", law__kf=1.0
    )
    assert np.array_equal(q[:2000], run_session(cfg).q)


def launch_cli(*args: str, env=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [tool("haptic-launch"), *args],
        capture_output=True,
        text=True,
        timeout=60,
        env=env or isolated_env(),
    )


@pytest.mark.parametrize(
    ("args", "message"),
    [
        (["no_such_config"], "ERROR: no config 'no_such_config'"),
        (["slide_sim", "--set", "controller_node"], "ERROR: --set needs NODE:PARAM=VALUE"),
        (["slide_sim", "--set", "pilot_node:kf=1"], "ERROR: --set names unknown node 'pilot_node'"),
        (["slide_sim", "--set", "controller_node:kf=[1"], "the value is not valid YAML"),
        (["slide_sim", "--rt-priority", "0"], "ERROR: --rt-priority 0: must be 1 to 99"),
        (["slide_sim", "--pin"], "ERROR: --pin places node processes on CPUs"),
        (["slide_sim", "--pin", "--composed"], "ERROR: --pin places node processes on CPUs"),
        (["slide_sim", "--processes", "--composed"], "ERROR: --composed, --processes and --group"),
        (["slide_sim", "--group", "device_node,pilot_node"], "--group names unknown node(s)"),
        (
            ["slide_sim", "--group", "device_node,controller_node", "--group", "device_node"],
            "ERROR: --group: device_node named in more than one place",
        ),
    ],
)
def test_bad_input_gets_one_error_line(args, message) -> None:
    out = launch_cli(*args)
    assert out.returncode == 2, out.stderr
    assert message in out.stderr and "Traceback" not in out.stderr


def test_config_errors_are_reported(tmp_path) -> None:
    bad = tmp_path / "bad.yaml"
    bad.write_text("pilot_node:\n  ros__parameters: {kf: 1}\n")
    out = launch_cli(str(bad))
    assert out.returncode == 2 and "unknown node(s) pilot_node" in out.stderr
    bad.write_text("controller_node: [1, 2\n")
    out = launch_cli(str(bad))
    assert out.returncode == 2 and "is not valid YAML" in out.stderr
    bad.write_text("controller_node:\n  kf: 1\n")
    out = launch_cli(str(bad))
    assert out.returncode == 2 and "has no ros__parameters" in out.stderr


@pytest.mark.multiprocess
def test_a_refused_node_parameter_stops_the_graph_with_its_reason(root, tmp_path) -> None:
    out = launch_cli(str(root / "config" / "slide_sim.yaml"), "--set", "controller_node:kf=-3")
    assert out.returncode == 1
    assert "parameter kf refused" in out.stderr
    line = next(x for x in out.stderr.splitlines() if "exited with code 2" in x)
    assert line.startswith("ERROR: the process of ") and "controller_node" in line, out.stderr


@pytest.mark.multiprocess
def test_record_option_writes_a_complete_bag(root, tmp_path) -> None:
    """--record adds a recorder the device waits for: every sample of the run is in the bag."""
    import json as _json

    bag = tmp_path / "run"
    out = launch_cli(
        str(root / "config" / "slide_sim.yaml"),
        "--record",
        str(bag),
        "--set",
        "device_node:duration_s=3.0",
    )
    assert out.returncode == 0, out.stderr
    res = subprocess.run(
        [tool("haptic-analyze"), str(bag), "--json"], capture_output=True, text=True, timeout=60
    )
    assert res.returncode == 0, res.stderr
    (seg,) = _json.loads(res.stdout)
    assert seg["missing_samples"] == 0 and seg["controller"] == "OL"
    assert seg["duration_s"] == pytest.approx(3.0, abs=0.002)
    again = launch_cli(str(root / "config" / "slide_sim.yaml"), "--record", str(bag))
    assert again.returncode == 2 and "exists already" in again.stderr


def test_rt_priority_without_permission_is_one_line(monkeypatch) -> None:
    from haptic_dob.errors import InputError
    from haptic_dob.launcher import set_rt_priority

    def refuse(*_args: object) -> None:
        raise PermissionError(1, "Operation not permitted")

    monkeypatch.setattr(os, "sched_setscheduler", refuse)
    with pytest.raises(InputError, match=r"not permitted .* needs root, CAP_SYS_NICE"):
        set_rt_priority(10)


@pytest.mark.skipif(os.geteuid() != 0, reason="SCHED_FIFO needs root here")
def test_rt_priority_runs_the_nodes_under_sched_fifo(root, tmp_path) -> None:
    """The loop's nodes under SCHED_FIFO; a recorder, off the command's path, at normal
    scheduling (at the loop's priority it held a CPU from the driver)."""
    args = ["--rt-priority", "10", "--record", str(tmp_path / "bag")]
    out = launch_cli("slide_sim", *args, "--set", "device_node:duration_s=0.5")
    assert out.returncode == 0, out.stderr
    assert "scheduling SCHED_FIFO priority 10" in out.stderr
    assert re.search(r"recording \d+ topic\(s\) to .*, scheduling normal", out.stderr), out.stderr


def _affinity_of_every_thread(pid: int) -> set[int]:
    """The CPUs any thread of process ``pid`` may run on."""
    cpus: set[int] = set()
    for tid in os.listdir(f"/proc/{pid}/task"):
        try:
            cpus |= os.sched_getaffinity(int(tid))
        except ProcessLookupError:  # a thread that just ended
            continue
    return cpus


@pytest.mark.multiprocess
@pytest.mark.skipif(len(os.sched_getaffinity(0)) < 2, reason="--pin needs 2 CPUs")
def test_pin_runs_each_node_process_on_its_planned_cpu(root, tmp_path) -> None:
    """Every thread of each node process (the middleware's too) runs on the CPU of the plan."""
    from haptic_dob.runtime.cpus import available_cpus, placement

    plan = placement(list(NODE_NAMES.values()), available_cpus())
    log = tmp_path / "launch.log"
    proc = launch(
        "slide_sim",
        isolated_env(),
        ["device_node:clock_mode=realtime", "device_node:duration_s=0.0"],
        log,
        ["--pin", "--processes"],
    )
    try:
        wait_until(
            lambda: log.read_text().count("process pinned") >= 4,
            60,
            poll_s=0.2,
            check=running(proc, log),
        )
        text = log.read_text()
        assert text.count("process pinned") == 4, text
        kids = children_of(proc.proc.pid)
        seen = {}
        for pid in kids:
            cmdline = Path(f"/proc/{pid}/cmdline").read_text(encoding="utf-8")
            name = next(n for exe, n in NODE_NAMES.items() if exe in cmdline)
            seen[name] = sorted(_affinity_of_every_thread(pid))
        assert seen == plan, text
        for name, cpus in plan.items():
            assert f"[{name}]: process pinned to CPU {cpus[0]}" in text
    finally:
        code = proc.stop()
    assert code == 0, log.read_text()


@pytest.mark.multiprocess
def test_an_unusable_cpu_affinity_stops_the_graph_with_its_reason() -> None:
    out = launch_cli("slide_sim", "--set", "device_node:cpu_affinity=[4096]")
    assert out.returncode == 1
    assert "ERROR: cpu_affinity: CPU 4096 not available to this process" in out.stderr
    assert "device_node exited with code 2" in out.stderr and "Traceback" not in out.stderr


def _holds_cpu_latency(pid: int) -> bool:
    """Whether process ``pid`` has ``/dev/cpu_dma_latency`` open."""
    fds = Path(f"/proc/{pid}/fd")
    return any(os.readlink(fds / fd) == "/dev/cpu_dma_latency" for fd in os.listdir(fds))


@pytest.mark.multiprocess
@pytest.mark.skipif(not can_request_cpu_latency(), reason="PM QoS requests need root")
def test_cpu_latency_is_held_while_the_graph_runs_and_withdrawn_after(tmp_path) -> None:
    """Each loop node process holds the request; the kernel applies it until the graph stops."""
    from haptic_dob.runtime.cpu_latency import current

    before = current()
    if before == 0:
        pytest.skip("another process holds a 0 us request already")
    log = tmp_path / "launch.log"
    proc = launch(
        "slide_sim",
        isolated_env(),
        ["device_node:clock_mode=realtime", "device_node:duration_s=0.0"],
        log,
        ["--cpu-latency", "0", "--processes"],
    )
    try:
        wait_until(
            lambda: log.read_text().count("held at 0 us") >= 4,
            60,
            poll_s=0.2,
            check=running(proc, log),
        )
        text = log.read_text()
        for name in NODE_NAMES.values():
            assert f"[{name}]: CPU wake-up latency held at 0 us" in text, text
        assert current() == 0
        holders = [pid for pid in children_of(proc.proc.pid) if _holds_cpu_latency(pid)]
        assert len(holders) == 4, text  # each node process holds its own request
    finally:
        code = proc.stop()
    assert code == 0, log.read_text()
    assert current() == before  # every process closed its request


@pytest.mark.skipif(can_request_cpu_latency(), reason="this run may make PM QoS requests")
def test_cpu_latency_without_access_is_refused_before_any_node_starts() -> None:
    out = launch_cli("slide_sim", "--cpu-latency", "0")
    assert out.returncode == 2
    assert "ERROR: --cpu-latency 0: cpu_latency_us: cannot open /dev/cpu_dma_latency" in out.stderr
    assert "exited with code" not in out.stderr and "Traceback" not in out.stderr


@pytest.mark.multiprocess
def test_a_graph_stopped_while_its_nodes_start_stops_quietly() -> None:
    """Stopped while its nodes still import their modules: no traceback, nothing killed."""
    out = launch_cli("slide_sim", "--duration", "0.05")
    assert out.returncode == 0, out.stderr
    assert "Traceback" not in out.stderr and "did not stop" not in out.stderr, out.stderr


@pytest.mark.parametrize(
    ("args", "code", "message"),
    [
        ([], 2, "ERROR: name at least one node to run"),
        (["device_node", "pilot_node"], 2, "ERROR: unknown node(s) pilot_node; nodes:"),
        (["device_node", "device_node"], 2, "ERROR: a node is named twice"),
        (["device_node", "--ros-args", "-r", "__node:=x"], 2, "__node:= would give every node"),
        (["--help"], 0, "usage: container [NODE ...]"),
    ],
)
def test_the_container_answers_bad_arguments_with_one_line(args, code: int, message: str) -> None:
    out = subprocess.run(
        [tool("haptic-container"), *args], capture_output=True, text=True, timeout=60
    )
    assert out.returncode == code, out.stderr
    assert message in out.stdout + out.stderr and "Traceback" not in out.stderr
