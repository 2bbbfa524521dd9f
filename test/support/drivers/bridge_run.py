"""A bridge to a test driver, started the ``ros2 run`` way, with the loop played by the test.

``BridgeRun`` starts the forcedimension_ros2-like test driver, ``haptic-bridge-node`` in
``/haptic`` with ``config/bridge_forcedimension.yaml``'s settings and the test's overrides
(waiting only for the stand-in controller), and the ``LoopStandIn`` answering its samples. The
test stops them in the order it studies; ``finish`` stops what is left and reads the driver's
truth.
"""

from __future__ import annotations

import json
import secrets
from pathlib import Path
from typing import Any

from haptic_dob.runtime.params import load_sections
from haptic_dob.runtime.params_file import dump_params
from support.drivers.run import Truth, start
from support.drivers.stand_in import Answer, LoopStandIn
from support.paths import BIN, ROOT
from support.rosgraph import Process, isolated_env

FD_CONFIG = ROOT / "config" / "bridge_forcedimension.yaml"
NS = "/haptic"


def bridge_params(config: Path, overrides: dict[str, Any], directory: Path) -> Path:
    """A params file with the config's ``/**`` and ``/**/bridge_node`` values and
    ``overrides`` (a relative ``urdf_path`` made absolute)."""
    sections = load_sections(config)
    values = {**sections.get("/**", {}), **sections.get("/**/bridge_node", {}), **overrides}
    if "urdf_path" in values and not Path(values["urdf_path"]).is_absolute():
        values["urdf_path"] = str(config.parent / values["urdf_path"])
    path = directory / "bridge_params.yaml"
    path.write_text(dump_params({"/**/bridge_node": {"ros__parameters": values}}))
    return path


class BridgeRun:
    """The FD-like test driver, its bridge and the loop's stand-in, running."""

    def __init__(self, directory: Path, answer: Answer, **overrides: Any) -> None:
        self.directory = directory
        self.env = isolated_env()
        self.stats = directory / "bridge.json"
        token = secrets.token_hex(8)  # as haptic-launch writes it for a device end and its source
        settings = {
            "command_token": token,
            "wait_for": ["controller_node"],
            "start_delay_s": 0.2,
            "stats_file": str(self.stats),
            # a Python test driver beside a CPU hog stalls for more than 10 ms now and then:
            # 50 ms keeps the state watchdog for the test that stops the state
            "state.timeout_s": 0.05,
            **overrides,
        }
        params = bridge_params(FD_CONFIG, settings, directory)
        self.driver = start({"kind": "fd", "rate_hz": 1000.0}, self.env, directory / "fd")
        self.loop = LoopStandIn(self.env, NS, answer, token)
        argv = [str(BIN / "haptic-bridge-node"), "--ros-args", "--params-file", str(params)]
        argv += ["-r", f"__ns:={NS}"]
        self.bridge = Process(argv, self.env, directory / "bridge.log")

    def stop_bridge(self) -> int | None:
        """Stop the bridge (SIGINT) and return its exit code."""
        return self.bridge.stop()

    def finish(self) -> Truth:
        """Stop everything left (bridge, stand-in, driver) and read the driver's truth."""
        self.bridge.stop()
        self.loop.close()
        self.driver.stop()
        return Truth.read(self.directory / "fd")

    def counts(self) -> dict[str, Any]:
        """The bridge's stats file (after it stopped)."""
        return dict(json.loads(self.stats.read_text()))
