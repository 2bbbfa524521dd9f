"""The ros2 run contract: executables resolved through the ament index start and stop cleanly."""

from __future__ import annotations

import functools
import os
import signal
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

import pytest
from ament_index_python.packages import get_package_prefix

from support.rosgraph import isolated_env, private_context
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess]

EXECUTABLES = [
    ("haptic_sim", "device_node"),
    ("haptic_dob", "environment_node"),
    ("haptic_dob", "observer_node"),
    ("haptic_dob", "controller_node"),
]


def node_names(env: dict[str, str]) -> set[str]:
    """Names of the nodes visible on the domain (via a short-lived rclpy context)."""
    import rclpy

    with private_context(domain=env["ROS_DOMAIN_ID"]) as ctx:
        probe = rclpy.create_node("probe", context=ctx)

        def names_now() -> set[str]:
            return {n for n, _ in probe.get_node_names_and_namespaces()}

        wait_until(lambda: len(names_now()) > 1, 15, poll_s=0.1)
        names = names_now()
        probe.destroy_node()
        return names


@pytest.mark.parametrize(("package", "name"), EXECUTABLES, ids=[e for _, e in EXECUTABLES])
def test_executable_resolves_starts_and_stops_on_sigint(package: str, name: str) -> None:
    exe = Path(get_package_prefix(package)) / "lib" / package / name
    assert exe.is_file() and os.access(exe, os.X_OK)
    env = isolated_env()
    proc = subprocess.Popen(
        [str(exe), "--ros-args", "-p", "clock_mode:=realtime"]
        if name == "device_node"
        else [str(exe)],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        start_new_session=True,
    )
    try:
        assert name in node_names(env)
        os.killpg(proc.pid, signal.SIGINT)
        out, _ = proc.communicate(timeout=15)
        assert proc.returncode == 0, out.decode()
        assert b"Traceback" not in out
    finally:
        if proc.poll() is None:
            os.killpg(proc.pid, signal.SIGKILL)
            proc.wait(5)


@pytest.mark.parametrize("after_exec_s", [0.0, 0.02, 0.04, 0.06, 0.1])
def test_ctrl_c_before_the_node_code_runs_prints_nothing(after_exec_s: float) -> None:
    """A SIGINT while the interpreter starts (its site packages, the console script's imports:
    before the entry point can set its quiet handler; here some 40-60 ms after the shim's exec,
    where Python printed a KeyboardInterrupt traceback and exited 1) prints nothing: the shim
    keeps SIGINT ignored until the entry point takes it, and a second SIGINT once rclpy is
    loaded ends the node quietly. The delays after the exec are the stimulus, not a bound."""
    exe = Path(get_package_prefix("haptic_dob")) / "lib" / "haptic_dob" / "controller_node"
    proc = subprocess.Popen(
        [str(exe)], env=isolated_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT
    )
    try:
        wait_until(lambda: _is_python(proc.pid), 30.0, poll_s=0.0005)  # a hang guard
        time.sleep(after_exec_s)
        proc.send_signal(signal.SIGINT)
        # a hang guard: the node ends, or goes on starting
        wait_until(
            lambda: proc.poll() is not None or _mapped(proc.pid, PHASES["rclpy_loaded"]),
            60.0,
            poll_s=0.002,
        )
        if proc.poll() is None:
            proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=30)  # a lost second signal: TimeoutExpired
        assert b"Traceback" not in out and b"KeyboardInterrupt" not in out, out.decode()
        assert b"Fatal Python error" not in out, out.decode()
        assert proc.returncode == 0, (proc.returncode, out.decode())
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)


def _is_python(pid: int) -> bool:
    """Whether process ``pid`` runs the Python interpreter (the shim has exec'd it)."""
    try:
        return "python" in os.readlink(f"/proc/{pid}/exe")
    except OSError:
        return False


def _mapped(pid: int, library: str) -> bool:
    """Whether process ``pid`` has a shared object whose path contains ``library`` mapped."""
    try:
        return library in Path(f"/proc/{pid}/maps").read_text()
    except OSError:
        return False


#: start-up phases at which the signal comes: the node's imports under way (numpy's extension
#: mapped, rclpy's not yet or just), rclpy loaded (its extension mapped; node being built), the
#: node built (its first line printed), and the device waiting for the graph before sample 0
PHASES = {"importing": "_multiarray_umath", "rclpy_loaded": "_rclpy_pybind11"}
PRINTED = {"built": "simulated slide device", "discovery": "waiting before sample 0"}


#: what each executable is started with (the container: the loop's four nodes, as ros2 launch's)
START_ARGS = {"container": ["device_node", "environment_node", "observer_node", "controller_node"]}


class Output:
    """What a child process prints, read line by line in a thread (the pipe never fills)."""

    def __init__(self, proc: subprocess.Popen[bytes]) -> None:
        self.lines: list[str] = []
        assert proc.stdout is not None
        self._thread = threading.Thread(target=self._read, args=(proc.stdout,), daemon=True)
        self._thread.start()

    def _read(self, stream: Any) -> None:
        for line in iter(stream.readline, b""):
            self.lines.append(line.decode(errors="replace"))

    def has(self, text: str) -> bool:
        return any(text in line for line in list(self.lines))

    def text(self, proc: subprocess.Popen[bytes]) -> str:
        proc.wait(30)  # a lost signal: TimeoutExpired
        self._thread.join(10)
        return "".join(self.lines)


@pytest.mark.parametrize("sig", [signal.SIGINT, signal.SIGTERM], ids=["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("phase", [*PHASES, *PRINTED])
@pytest.mark.parametrize(
    ("package", "name"),
    [("haptic_sim", "device_node"), ("haptic_dob", "controller_node"), ("haptic_dob", "container")],
    ids=["device_node", "controller_node", "container"],
)
def test_a_signal_during_start_up_ends_quietly_with_0(
    package: str, name: str, phase: str, sig: signal.Signals
) -> None:
    """``ros2 launch`` or a terminal sends SIGINT (``ros2 launch`` SIGTERM after it) while the
    node still imports numpy, pinocchio and rclpy, builds itself or waits for the graph: it ends
    at once with exit 0, as ``ros2 launch`` counts a clean end, never with a traceback, and the
    signal is never lost. Each phase is reached by what the process did (a library mapped, a line
    printed), not by a delay. (A SIGINT within the interpreter's own first tenth of a second,
    before the entry point runs, is ignored by the shim; ``test_ctrl_c_before_the_node_code``.)"""
    if phase in PRINTED and name == "controller_node":
        pytest.skip("the controller prints nothing while it starts")
    if phase == "discovery" and name == "container":
        pytest.skip("the composed loop does not wait for the graph long")
    exe = Path(get_package_prefix(package)) / "lib" / package / name
    proc = subprocess.Popen(
        [str(exe), *START_ARGS.get(name, [])],
        env=isolated_env(),
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    out = Output(proc)
    try:
        # a hang guard: the phase comes within the start-up
        if phase in PHASES:
            reached = wait_until(lambda: _mapped(proc.pid, PHASES[phase]), 60.0, poll_s=0.002)
        else:
            reached = wait_until(lambda: out.has(PRINTED[phase]), 60.0, poll_s=0.002)
        assert reached and proc.poll() is None, out.text(proc)
        proc.send_signal(sig)
        text = out.text(proc)
        assert "Traceback" not in text and "KeyboardInterrupt" not in text, text
        assert proc.returncode == 0, (proc.returncode, text)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)


def test_the_container_runs_the_loop_nodes_its_params_file_names(root) -> None:
    """``ros2 run haptic_dob container --ros-args --params-file FILE``, as the docs write it, runs
    the nodes the file's sections name (it exited 2, "name at least one node to run")."""
    exe = Path(get_package_prefix("haptic_dob")) / "lib" / "haptic_dob" / "container"
    env = isolated_env()
    config = root / "config" / "slide_sim.yaml"
    proc = subprocess.Popen(
        [str(exe), "--ros-args", "--params-file", str(config), "-p", "device_node:duration_s:=0.0"],
        env=env,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
    )
    out = Output(proc)
    try:
        loop = {"device_node", "environment_node", "observer_node", "controller_node"}

        def all_up() -> bool:
            return proc.poll() is not None or loop <= node_names(env)

        assert wait_until(all_up, 60, poll_s=0.5) and proc.poll() is None, out.text(proc)
        proc.send_signal(signal.SIGINT)
        text = out.text(proc)
        assert proc.returncode == 0, text
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)


def test_a_bare_p_that_a_node_section_shadows_is_said_with_what_to_type(root) -> None:
    """``--params-file config/slide_sim.yaml -p clock_mode:=realtime``: the file's device section
    wins (rcl's order) and the device says so at start-up, with the form that reaches it; typed
    that way, the device runs in real time."""
    exe = Path(get_package_prefix("haptic_sim")) / "lib" / "haptic_sim" / "device_node"
    config = str(root / "config" / "slide_sim.yaml")
    said: list[str] = []
    for rule in ("clock_mode:=realtime", "device_node:clock_mode:=realtime"):
        proc = subprocess.Popen(
            [str(exe), "--ros-args", "--params-file", config, "-p", rule],
            env=isolated_env(),
            stdout=subprocess.PIPE,
            stderr=subprocess.STDOUT,
        )
        out = Output(proc)
        try:
            built = functools.partial(out.has, "simulated slide device")
            assert wait_until(built, 60, poll_s=0.01), out.text(proc)
            proc.send_signal(signal.SIGINT)
            said.append(out.text(proc))
        finally:
            if proc.poll() is None:
                proc.kill()
                proc.wait(5)
    bare, qualified = said
    shadow = [line for line in bare.splitlines() if "ignored -p clock_mode:=realtime" in line]
    assert len(shadow) == 1 and "lockstep" in bare, bare
    assert "type -p device_node:clock_mode:=realtime after the last --params-file" in shadow[0]
    assert "realtime at 1000 Hz" in qualified and "ignored" not in qualified, qualified
