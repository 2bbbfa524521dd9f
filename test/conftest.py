"""Shared test helpers."""

from __future__ import annotations

import os
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent


@pytest.fixture
def root() -> Path:
    """The repository root."""
    return ROOT


def tool(name: str) -> str:
    """Path of a console script installed next to the running interpreter."""
    path = BIN / name
    assert path.exists(), f"{name} is not installed in {BIN}"
    return str(path)


@pytest.fixture
def context(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """An initialised rclpy context of its own on a random ROS domain (shut down after)."""
    import rclpy
    from rclpy.context import Context

    from rosgraph import isolated_env

    env = isolated_env()
    monkeypatch.setenv("ROS_DOMAIN_ID", env["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(context=ctx, args=[])
    yield ctx
    rclpy.try_shutdown(context=ctx)


@pytest.fixture(autouse=True)
def _no_ros_domain_leak(monkeypatch: pytest.MonkeyPatch) -> None:
    """Tests never talk to a lab network: discovery stays on this host."""
    monkeypatch.setenv(
        "ROS_AUTOMATIC_DISCOVERY_RANGE",
        os.environ.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "LOCALHOST"),
    )


def can_request_cpu_latency() -> bool:
    """Whether this test run may make PM QoS requests: the device opens for writing (root, and
    no container rule against it). An open without a write makes no request."""
    from haptic_dob.runtime.cpu_latency import PM_QOS_PATH

    try:
        os.close(os.open(PM_QOS_PATH, os.O_RDWR))
    except OSError:
        return False
    return True
