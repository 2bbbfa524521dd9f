"""An error out of a node's callback ends the process, but every loop node's shutdown runs
first: a bridge composed with the loop still sends its zero when the controller beside it
raises."""

from __future__ import annotations

import os
from typing import Any, ClassVar

import pytest

from haptic_dob.runtime.ros.spin import LoopNode, run_nodes
from support.rosgraph import isolated_env


class Raising(LoopNode):
    """A loop node whose wake-up raises (a law that throws, say)."""

    def next_wakeup(self) -> float | None:
        return 0.0

    def on_wakeup(self, now: float) -> None:
        raise RuntimeError("the law threw")


class Zeroing(LoopNode):
    """A loop node that records its shutdown (a bridge sending zero)."""

    shut: ClassVar[list[str]] = []

    def on_shutdown(self) -> None:
        Zeroing.shut.append(self.get_name())


def test_every_loop_node_shuts_down_after_an_error(monkeypatch: Any) -> None:
    for key, value in isolated_env().items():
        if key.startswith("ROS_"):
            monkeypatch.setenv(key, value)

    def make(ctx: Any) -> list[LoopNode]:
        return [Zeroing("bridge_node", context=ctx), Raising("controller_node", context=ctx)]

    with pytest.raises(RuntimeError, match="the law threw"):
        run_nodes(make, ["test"])
    assert Zeroing.shut == ["bridge_node"]
    assert os.environ.get("ROS_DOMAIN_ID")
