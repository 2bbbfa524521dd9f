"""Two hosts on this machine: the device in one network namespace, the rest in another.

The namespaces are joined by a veth pair (addresses inside 10.231.x only). The loop closes across
them with ``--network subnet``; taking the link down makes the device's watchdog zero the force
within ``command_timeout_s``; bringing it up resumes the loop. Needs root and ``ip`` (iproute2).
"""

from __future__ import annotations

import re
import sys
import time
from pathlib import Path

import numpy as np
import pytest

from support.capacity import require_realtime
from support.netns import in_ns, ip, lab_hosts
from support.rosgraph import isolated_env
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

BIN = Path(sys.executable).parent
# the watchdog trips at the first tick after command_timeout_s without a command; the zero effort
# shows in the sample after that tick: the held effort lasts at most the timeout + 2 periods
TIMEOUT_S, PERIOD_S = 0.005, 0.001


@pytest.fixture
def hosts():
    """Two network namespaces joined by a veth pair; yields (nsA, nsB, ifA)."""
    with lab_hosts() as made:
        yield made


def read(csv: Path) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    rows = [r.split(",") for r in csv.read_text().splitlines() if r.count(",") == 2]
    arr = np.array(rows, dtype=float)
    return arr[:, 0], arr[:, 1] * 1e-9, arr[:, 2]


def wait_live(csv: Path, since: float, timeout: float) -> bool:
    """Wait until 300 samples after ``since`` carry a non-zero effort."""

    def live() -> bool:
        if not (csv.exists() and csv.stat().st_size):
            return False
        t, _, e = read(csv)
        return bool(np.sum((t > since) & (np.abs(e) > 0.1)) > 300)

    return wait_until(live, timeout, poll_s=0.3)


def test_loop_across_two_hosts_and_a_link_failure(hosts, root, tmp_path) -> None:
    require_realtime([["environment_node", "observer_node", "controller_node"]])
    ns_a, ns_b, dev_a = hosts
    env = isolated_env()
    env.pop("ROS_AUTOMATIC_DISCOVERY_RANGE")
    config = str(root / "config" / "slide_sim.yaml")
    launch = str(BIN / "haptic-launch")
    csv = tmp_path / "efforts.csv"
    procs = [
        in_ns(
            ns_a,
            [str(BIN / "python"), str(root / "test" / "support" / "netns_monitor.py"), str(csv)],
            env,
            tmp_path / "monitor.log",
        ),
        in_ns(
            ns_b,
            [
                launch,
                config,
                "--network",
                "subnet",
                "--only",
                "environment_node,observer_node,controller_node",
            ],
            env,
            tmp_path / "b.log",
        ),
        in_ns(
            ns_a,
            [
                launch,
                config,
                "--network",
                "subnet",
                "--only",
                "device_node",
                "--set",
                "device_node:clock_mode=realtime",
                "--set",
                "device_node:duration_s=0.0",
                "--set",  # a fine encoder: every command differs from the one before it, so the
                "device_node:plant.encoder_resolution_m=1.0e-9",  # run of equal efforts below
            ],  # starts exactly at the last command the device received
            env,
            tmp_path / "a.log",
        ),
    ]

    def trips() -> list[str]:
        """How long the device held its last command before each trip it said (samples)."""
        text = (tmp_path / "a.log").read_text()
        return re.findall(r"no valid effort_command for (\d+) samples", text)

    try:
        assert wait_live(csv, 0.0, 60), (tmp_path / "a.log").read_text()[-2000:]
        before = len(trips())
        t_down = time.monotonic()
        ip("-n", ns_a, "link", "set", dev_a, "down")
        time.sleep(1.5)
        t_up = time.monotonic()
        ip("-n", ns_a, "link", "set", dev_a, "up")
        assert wait_live(csv, t_up, 60), "the loop did not resume after the link came back"
        t, _, e = read(csv)
        down = (t > t_down + 0.3) & (t < t_up)
        assert down.sum() > 500 and np.all(e[down] == 0.0), "force not zero while the link is down"

        # on the device's clock: the last command it received held until the watchdog zeroed the
        # effort, at the first sample past the timeout; the device says after how many samples
        # (its first trip after the link went down: a start-up trip may come before it)
        assert wait_until(lambda: len(trips()) > before, 10), (
            "the watchdog did not say it tripped: " + (tmp_path / "a.log").read_text()[-2000:]
        )
        silent = int(trips()[before])
        assert silent == round(TIMEOUT_S / PERIOD_S) + 1, trips()
        # the monitor agrees: the last effort before the zeros was held at least that long (longer
        # when the controller's last commands were equal: it saw some inputs stop before others)
        window = (t > t_down - 0.5) & (t < t_up)
        ew = e[window]
        last = np.nonzero(ew != 0.0)[0][-1]
        assert np.all(ew[last - silent + 1 : last + 1] == ew[last]), ew[last - silent : last + 2]
    finally:
        for p in reversed(procs):
            p.stop()
