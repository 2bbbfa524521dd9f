"""Markers by directory, and the fixtures every test may use.

``test/unit/`` holds the tests that neither talk DDS nor start node processes, ``test/graph/``
those that do (marked ``dds``), ``test/graph/realtime/`` those whose premise is real time at
1 kHz (marked ``dds`` and ``alone``); ``test/support/`` holds the helpers. ``make test`` runs the
unit tests on every CPU, then the ``dds`` ones two at a time, then the ``alone`` ones one at a
time, alone on the machine.
"""

from __future__ import annotations

import os
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest

from haptic_dob.runtime.ros.dds_profile import use_default_profile
from support.paths import ROOT

# the tests' own endpoints (collectors, a driver's controls) speak DDS as the suite's processes
# do: the profile's 50 ms heartbeats repair a lost discovery message in time for a short run
use_default_profile()

GRAPH = ROOT / "test" / "graph"
REALTIME = GRAPH / "realtime"


def pytest_collection_modifyitems(config: pytest.Config, items: list[pytest.Item]) -> None:
    """Mark ``dds`` every test under ``test/graph/``, and ``alone`` those under its ``realtime/``;
    a test elsewhere that asks for an rclpy context is misplaced and fails at once."""
    for item in items:
        path = Path(item.path)
        if path.is_relative_to(GRAPH):
            item.add_marker(pytest.mark.dds)
            if path.is_relative_to(REALTIME):
                item.add_marker(pytest.mark.alone)
        elif "context" in getattr(item, "fixturenames", ()):
            raise pytest.UsageError(f"{item.nodeid} uses an rclpy context: move it to test/graph/")


@pytest.fixture
def root() -> Path:
    """The repository root."""
    return ROOT


@pytest.fixture
def context(monkeypatch: pytest.MonkeyPatch) -> Iterator[Any]:
    """An initialised rclpy context of its own on a random ROS domain (shut down after)."""
    import rclpy  # only the graph tests use it: the unit tests never load rclpy
    from rclpy.context import Context

    from support.rosgraph import isolated_env

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
