"""Shared test helpers."""

from __future__ import annotations

import os
import re
import sys
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

ROOT = Path(__file__).resolve().parents[1]
BIN = Path(sys.executable).parent
#: what marks a test module as one that talks DDS or starts node processes: it imports rclpy,
#: the ROS message layer or a test helper that starts processes
_DDS_MODULE = re.compile(
    r"^\s*(from|import) "
    r"(rclpy|haptic_msgs_py\.ros|rosgraph|ros2bag_session|netns_monitor|capacity)\b",
    re.MULTILINE,
)
_DDS_SOURCES: dict[str, bool] = {}
#: what marks a DDS test module as one to run alone on the machine: its premise is real time at
#: 1 kHz, so it measures what the machine can carry (``capacity``) and that must be the machine's
_ALONE_MODULE = re.compile(r"^\s*(from|import) capacity\b", re.MULTILINE)
_ALONE_SOURCES: dict[str, bool] = {}


def _talks_dds(item: pytest.Item) -> bool:
    if item.get_closest_marker("multiprocess") or "context" in getattr(item, "fixturenames", ()):
        return True
    path = str(item.path)
    if path not in _DDS_SOURCES:
        _DDS_SOURCES[path] = bool(_DDS_MODULE.search(Path(path).read_text(encoding="utf-8")))
    return _DDS_SOURCES[path]


def _alone(item: pytest.Item) -> bool:
    path = str(item.path)
    if path not in _ALONE_SOURCES:
        text = Path(path).read_text(encoding="utf-8")
        _ALONE_SOURCES[path] = bool(_ALONE_MODULE.search(text))
    return _ALONE_SOURCES[path]


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark ``dds`` every test of a module that talks DDS or starts node processes (see
    ``_DDS_MODULE``), and every test that uses the ``context`` fixture; of those, mark ``alone``
    the ones whose module has real time as a premise (``_ALONE_MODULE``). ``make test`` runs the
    others first on every CPU, then the ``dds`` ones two at a time, then the ``alone`` ones one at
    a time, alone on the machine."""
    for item in items:
        if _talks_dds(item):
            item.add_marker(pytest.mark.dds)
            if _alone(item):
                item.add_marker(pytest.mark.alone)


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
