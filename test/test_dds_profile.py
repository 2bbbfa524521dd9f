"""The Fast DDS profile the suite's node processes start with (``runtime.ros.dds_profile``)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from haptic_dob.runtime.ros.dds_profile import (
    NEWER_PROFILES_ENV,
    PROFILE,
    PROFILES_ENV,
    use_default_profile,
)
from rosgraph import isolated_env

# a node process's start: the profile chosen, then a node with a reliable writer
START_A_WRITER = """
import rclpy
from std_msgs.msg import Header
from haptic_dob.runtime.ros.dds_profile import use_default_profile
print(use_default_profile())
rclpy.init()
node = rclpy.create_node("profile_check")
node.create_publisher(Header, "profile_check", 10)
node.destroy_node()
rclpy.shutdown()
"""


def test_the_suites_profile_applies_unless_the_user_gives_one(monkeypatch) -> None:
    for name in (PROFILES_ENV, NEWER_PROFILES_ENV):  # set, then removed: restored after the test
        monkeypatch.setenv(name, "x")
        monkeypatch.delenv(name)
    assert use_default_profile() == str(PROFILE) == os.environ[PROFILES_ENV]
    monkeypatch.setenv(PROFILES_ENV, "/somewhere/lab_profile.xml")
    assert use_default_profile() == "/somewhere/lab_profile.xml"
    monkeypatch.delenv(PROFILES_ENV)
    monkeypatch.setenv(NEWER_PROFILES_ENV, "/somewhere/fastdds3_profile.xml")
    assert use_default_profile() == "/somewhere/fastdds3_profile.xml"
    assert PROFILES_ENV not in os.environ


def _start(profile: Path | None) -> subprocess.CompletedProcess[str]:
    env = {k: v for k, v in isolated_env().items() if k not in (PROFILES_ENV, NEWER_PROFILES_ENV)}
    env["RMW_IMPLEMENTATION"] = "rmw_fastrtps_cpp"  # the profile is Fast DDS's
    if profile is not None:
        env[PROFILES_ENV] = str(profile)
    return subprocess.run(
        [sys.executable, "-c", START_A_WRITER], env=env, capture_output=True, text=True, timeout=60
    )


@pytest.mark.parametrize("broken", [False, True])
def test_fast_dds_parses_the_profile(tmp_path, broken: bool) -> None:
    """Fast DDS loads it without a parser error (a broken copy shows what a bad one prints)."""
    profile = None
    if broken:
        profile = tmp_path / "broken.xml"
        profile.write_text(PROFILE.read_text().replace("<sec>0</sec>", "<sec>zero</sec>"))
    run = _start(profile)
    assert run.returncode == 0, run.stderr
    assert run.stdout.split("\n")[0] == str(profile or PROFILE)
    assert ("XMLPARSER" in run.stdout + run.stderr) is broken, run.stdout + run.stderr  # its log
