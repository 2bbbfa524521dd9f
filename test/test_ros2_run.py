"""The ros2 run contract: executables resolved through the ament index start and stop cleanly."""

from __future__ import annotations

import os
import signal
import subprocess
import time
from pathlib import Path

import pytest
from ament_index_python.packages import get_package_prefix

from rosgraph import isolated_env

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
    from rclpy.context import Context

    saved = os.environ.get("ROS_DOMAIN_ID")
    os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
    ctx = Context()
    rclpy.init(context=ctx, args=[])
    try:
        probe = rclpy.create_node("probe", context=ctx)
        deadline = time.monotonic() + 15
        names: set[str] = set()
        while time.monotonic() < deadline:
            names = {n for n, _ in probe.get_node_names_and_namespaces()}
            if len(names) > 1:
                break
            time.sleep(0.1)
        probe.destroy_node()
        return names
    finally:
        rclpy.try_shutdown(context=ctx)
        if saved is None:
            os.environ.pop("ROS_DOMAIN_ID", None)
        else:
            os.environ["ROS_DOMAIN_ID"] = saved


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


@pytest.mark.parametrize("delay_s", [0.0, 0.3, 1.0, 2.5])
@pytest.mark.parametrize(
    ("package", "name"),
    [("haptic_sim", "device_node"), ("haptic_dob", "controller_node")],
    ids=["device_node", "controller_node"],
)
def test_ctrl_c_during_start_up_ends_quietly(package: str, name: str, delay_s: float) -> None:
    """``ros2 launch`` or a terminal sends SIGINT while the node still imports or starts: it
    ends with 0 (node up), 130 (still importing) or by the signal itself (before Python ran),
    never with a traceback."""
    exe = Path(get_package_prefix(package)) / "lib" / package / name
    proc = subprocess.Popen(
        [str(exe)], env=isolated_env(), stdout=subprocess.PIPE, stderr=subprocess.STDOUT
    )
    try:
        time.sleep(delay_s)
        proc.send_signal(signal.SIGINT)
        out, _ = proc.communicate(timeout=30)
        assert b"Traceback" not in out and b"KeyboardInterrupt" not in out, out.decode()
        assert proc.returncode in (0, 130, -signal.SIGINT), (proc.returncode, out.decode())
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(5)
