"""Start a test driver from a test, work its controls, read its truth.

``start`` writes the driver's config and starts ``drivers/node.py`` as a process of its own
(``rosgraph.Process``: its own session, stopped by SIGINT, killed if it lingers);
``bridge_session`` runs one beside ``haptic-launch`` of a bridge config. ``Controls``
holds one publisher per test control (transient local, so a message sent before the driver
matched still arrives): the stylus button, a pause of the state. ``Truth`` reads what the driver
wrote when it stopped.
"""

from __future__ import annotations

import json
import os
import sys
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from support.rosgraph import Process, isolated_env, launch
from support.waits import wait_until

NODE = Path(__file__).resolve().parent / "node.py"
DEADMAN_HELD = "dead-man held"  # the bridge's line when the button is held
LOOP_UP = "the loop is up"  # the bridge's line when it hands the driver's states on
DRIVER_SHARE = 0.95  # the test driver's ticks processed within a period of their instant
#: a test driver runs under SCHED_FIFO at this priority where the machine allows it, as a
#: controller manager's real-time thread does (a real driver keeps its rate beside a CPU hog)
DRIVER_RT_PRIORITY = 50
#: commands before the driver's next state, at least, for the teleoperated arm's estimate (a
#: late command delays the slave's loop a period). The loop's own timing (issue 31) is
#: BENCHMARKS.md's.
ON_TIME = 0.90
#: the same for the identification chain's figures: the bridge reports a late command where it
#: acts (by the driver's clock), and in batch half the commands late gave the figures of every
#: command on time (test/unit/bridge/test_bridge_chain.py); below that it was not measured
CHAIN_ON_TIME = 0.50

#: a hand like slide_sim's: a 2 N push with a slow semi-random swing, held by a soft grip
SLIDE_HAND = {
    "behaviour": "semi_random",
    "mass_kg": 0.1,
    "stiffness_n_per_m": 300.0,
    "damping_n_s_per_m": 10.0,
    "offset_m": 0.0091667,
    "amplitude_m": 0.0011458,
    "band_low_hz": 0.05,
    "band_high_hz": 10.0,
    "ramp_s": 1.0,
}


def start(
    cfg: dict[str, Any], env: dict[str, str], directory: Path, prefix: Sequence[str] = ()
) -> Process:
    """The driver of ``cfg`` (``node.py``'s keys; ``out`` defaults to ``directory``,
    ``rt_priority`` to ``DRIVER_RT_PRIORITY``), ticking (its start-up may take seconds on a
    loaded machine: a session started before would run without it). ``prefix`` goes before the
    command (``taskset -c 1``)."""
    directory.mkdir(parents=True, exist_ok=True)
    cfg = {"out": str(directory), "rt_priority": DRIVER_RT_PRIORITY, **cfg}
    path = directory / "driver.json"
    path.write_text(json.dumps(cfg))
    proc = Process([*prefix, sys.executable, str(NODE), str(path)], env, directory / "driver.log")
    if not wait_until(lambda: "ticking" in proc.output() or proc.proc.poll() is not None, 120.0):
        proc.stop()
        raise TimeoutError(f"the test driver did not start ticking:\n{proc.output()[-2000:]}")
    assert proc.proc.poll() is None, proc.output()[-2000:]
    return proc


def bridge_session(
    config: Path, driver: dict[str, Any], directory: Path, sets: Sequence[str], extra: Sequence[str]
) -> tuple[Truth, dict[str, Any]]:
    """The test driver of ``driver`` and ``haptic-launch config --namespace /haptic EXTRA --set
    SETS`` on a fresh domain, until the bridge's ``duration_s``; a Touch's white button is
    pressed once the bridge is up, as the user does. The driver's truth and the bridge's counts
    (its ``stats_file``, ``directory/bridge.json``); the launch's output in ``launch.log``."""
    env = isolated_env()
    stats = directory / "bridge.json"
    drv = start(driver, env, directory / "driver")
    controls = Controls(env, "/touch") if driver["kind"] == "touch" else None
    graph = launch(
        str(config),
        env,
        [f"bridge_node:stats_file={stats}", *sets],
        directory / "launch.log",
        extra=["--namespace", "/haptic", *extra],
    )
    try:
        if controls is not None:
            controls.hold(graph.output)
        assert graph.wait(180) == 0, graph.output()
    finally:
        graph.stop()
        if controls is not None:
            controls.close()
        drv.stop()
    return Truth.read(directory / "driver"), json.loads(stats.read_text())


class Controls:
    """The test's hand on a driver: its controls in namespace ``ns`` (a private context)."""

    def __init__(self, env: dict[str, str], ns: str) -> None:
        import rclpy
        from rclpy.context import Context
        from std_msgs.msg import Bool, Float64

        from support.drivers.speak import LATCHED

        self._saved = {
            k: os.environ.get(k) for k in ("ROS_DOMAIN_ID", "ROS_AUTOMATIC_DISCOVERY_RANGE")
        }
        os.environ["ROS_DOMAIN_ID"] = env["ROS_DOMAIN_ID"]
        os.environ["ROS_AUTOMATIC_DISCOVERY_RANGE"] = env["ROS_AUTOMATIC_DISCOVERY_RANGE"]
        self.context = Context()
        rclpy.init(context=self.context, args=[])
        self.node = rclpy.create_node(
            "test_hand", context=self.context, start_parameter_services=False
        )
        self._bool, self._float = Bool, Float64
        self._button = self.node.create_publisher(Bool, f"{ns}/test/button", LATCHED)
        self._pause = self.node.create_publisher(Float64, f"{ns}/test/pause", LATCHED)
        self._buttons = f"{ns}/buttons"  # the driver's Joy, which the bridge subscribes to

    def press(self, held: bool) -> None:
        """Hold (or let go of) the stylus's white button."""
        self._button.publish(self._bool(data=held))

    def hold(self, output: Callable[[], str], tries: int = 5, wait_s: float = 2.0) -> None:
        """Press the white button once the loop is up (``output``: the bridge's log so far) and
        the bridge subscribes to the driver's buttons, again until the bridge says it sees it
        held, as a user presses again: the driver publishes the button only on change, so a
        press before the bridge's subscription matched the driver's publisher is lost."""
        assert wait_until(lambda: LOOP_UP in output(), 120.0), output()[-2000:]
        wait_until(lambda: self.node.count_subscribers(self._buttons) > 0, 60.0)
        for _ in range(tries):
            self.press(True)
            if wait_until(lambda: DEADMAN_HELD in output(), wait_s):
                return
            self.press(False)
            time.sleep(0.5)  # the driver takes the release before the next press
        raise AssertionError(f"the bridge never saw the button held:\n{output()[-2000:]}")

    def pause(self, seconds: float) -> None:
        """The driver publishes no state for ``seconds`` from when it takes the message (sent
        once the driver subscribes: a message kept for a later match starts the pause late)."""
        assert wait_until(lambda: self._pause.get_subscription_count() > 0, 60.0)
        self._pause.publish(self._float(data=seconds))

    def close(self) -> None:
        import rclpy

        self.node.destroy_node()
        rclpy.try_shutdown(context=self.context)
        for k, v in self._saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


@dataclass(frozen=True)
class Truth:
    """What a driver wrote when it stopped: its counts and plant, and per cycle and command
    series (``ticks``: stamp ns, monotonic s, whether the state went out (1; 0: the test's
    pause held it; -1: the driver skipped the cycle, an overrun), q, the effort applied
    over the period before, hand force (3), tip (3); ``commands``: arrival (monotonic s), the
    stamp answered, values)."""

    info: dict[str, Any]
    ticks: np.ndarray
    commands: np.ndarray
    dof: int
    stamps: np.ndarray  # each tick's stamp (ns, int64): its instant on the system clock
    answered: np.ndarray  # the stamp each command answers (ns, int64; -1: none)
    late: np.ndarray  # each tick's processing after its instant (s)

    @classmethod
    def read(cls, directory: Path) -> Truth:
        info = json.loads((directory / "truth.json").read_text())
        data = np.load(directory / "series.npz")
        return cls(
            info,
            data["ticks"],
            data["commands"],
            int(data["dof"]),
            data["tick_stamps"],
            data["answered"],
            data["tick_late"],
        )

    @property
    def counts(self) -> dict[str, Any]:
        return dict(self.info["counts"])

    @property
    def times(self) -> np.ndarray:
        """Monotonic s of each tick (the test's clock too)."""
        return self.ticks[:, 1]

    @property
    def instants(self) -> np.ndarray:
        """Monotonic s of each tick's instant: it takes the commands DDS received before it,
        however late the tick itself is processed (``times``)."""
        return self.ticks[:, 1] - self.late

    @property
    def published(self) -> np.ndarray:
        return self.ticks[:, 2] > 0.5

    @property
    def paused(self) -> np.ndarray:
        """Ticks whose state the test's pause held back (not those an overrun skipped)."""
        return self.ticks[:, 2] == 0.0

    @property
    def q(self) -> np.ndarray:
        return self.ticks[:, 3 : 3 + self.dof]

    @property
    def applied(self) -> np.ndarray:
        """The effort applied over the period before each tick (joints; the Touch's Cartesian
        force in the model's axes)."""
        n = 3 if self.info["kind"] == "touch" else self.dof
        return self.ticks[:, 3 + self.dof : 3 + self.dof + n]

    def ticked_share(self) -> float:
        """The share of the driver's ticks processed within a period of their instant: 1 when
        it held its rate (a Python test driver on a loaded machine falls behind, which a real
        driver would not)."""
        period = 1.0 / float(self.info["rate_hz"])
        return float(np.mean(self.late < period)) if len(self.late) else 0.0

    def answered_share(self) -> float:
        """Of the states published from the first one a command answered to the last, the share
        some command answered (a gate that closed in between, or states lost, lower it)."""
        got = np.unique(self.answered[self.answered >= 0])
        got = got[got > 0]  # a bridge's zero before any state was handed on is stamped 0
        if len(got) == 0:
            return 0.0
        sent = self.stamps[self.published & (self.stamps >= got[0]) & (self.stamps <= got[-1])]
        return float(np.isin(sent, got).mean())

    @property
    def hand_start_ns(self) -> int:
        """The instant (ns) a Touch's plant first stepped from (its hand's time zero: the
        press of the white button, with a hand); -1 when it never left its rest or is no
        Touch."""
        return int(self.info.get("hand_start_ns", -1))

    def tick_of(self, stamp_ns: int) -> int:
        """The index of the tick whose state carried ``stamp_ns``."""
        return int(np.searchsorted(self.stamps, stamp_ns))

    @property
    def hand(self) -> np.ndarray:
        return self.ticks[:, -6:-3]

    @property
    def tip(self) -> np.ndarray:
        return self.ticks[:, -3:]
