"""The identification chain through the bridge, in real time, for each test driver (issue 31).

What docs/devices.md tells a lab to type, against a test driver whose plant's truth the test
knows: the excitation session (``haptic-launch <config> --params excite/<device> --record``) ->
``haptic-identify`` on that bag -> a recorded DOB session with that model, the simulated hand
pushing into the wall. The figure is the RMS of the estimate's 3-D error (matched by stamp with
the plant's hand force) over the true force's span, in contact from 2 s on (a Touch's: to 8 s
of its hand's time, the batch chain's window, ``test/unit/bridge/test_bridge_chain.py``).

- forcedimension_ros2-like (1 kHz, ``--axes``): mass 5 %, viscous friction 10 %, estimate 5 %.
- Touch-like (500 Hz, best-effort position-only states, the white button; ``--inertial``): the
  payload's gravity torque within 5 %, Coulomb friction within 20 %, viscous within 10 %; an OL
  session -> ``--velocity-noise`` (the Kalman velocity filter); the estimate within 5 %.
The loop runs under SCHED_FIFO and a PM QoS request where this machine allows them, as a lab
runs it. Each skips where this machine cannot carry the loop and its recorder in real time now."""

from __future__ import annotations

import json
import math
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from haptic_dob.bag.bagfile import open_bag
from haptic_dob.bag.cdr import decode_vectors
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models import UrdfModel
from haptic_dob.runtime.params import build, load_node_params, node_view
from support.capacity import hop_floor_us, require_path_latency, require_realtime
from support.drivers import plants, scheduling
from support.drivers.run import (
    CHAIN_ON_TIME,
    DRIVER_SHARE,
    SLIDE_HAND,
    Truth,
    bridge_session,
)
from support.paths import ROOT, tool

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

CONFIG = ROOT / "config"
SLIDE_LOOP = ["device_node", "environment_node", "observer_node", "controller_node"]
DOB_S = 8.0  # s: the DOB session; its figure's window is from SETTLE_S to its end
SETTLE_S = 2.0  # s: the hand's 1 s ramp and the loop's settling
#: a Touch's hand moves from the test's press of the white button on, once the loop is up and
#: the press can be heard (the test presses again, 2.5 s on, where the bridge did not see it):
#: the session runs this much longer, so that the figure covers the hand's time from SETTLE_S
#: to DOB_S, as the batch chain's does; a session that did not is said (the premise)
PRESS_S = 4.0
WRENCH = "geometry_msgs/msg/WrenchStamped"
#: the Touch chain's premise: its viscous friction, 1-2 mN m s/rad, is the figure the loop's
#: timing moves most. On a machine 2-3 times slower than usual (2026-11-28: stalls to 20 ms,
#: up to 3 % of the best-effort states lost) the shoulder's, fitted on the driver's own
#: efforts at every tick, came out -1, -6, -22 and -12 % in runs with 50-60 % of the commands
#: on time and +10 % at 88 %; the chain passed on usual days, 96-99.6 % on time (BENCHMARKS.md).
#: On 2026-11-29 (one raw hop 180-260 us) excitation sessions 91.1 and 93.7 % on time gave a
#: viscous friction 15 and 14 % off; 92.4 and 95.1 % passed
TOUCH_ON_TIME = 0.95
TOUCH_HAND = {
    k.removeprefix("hand."): v
    for k, v in load_node_params(plants.TOUCH_SIM)["device_node"].items()
    if k.startswith("hand.")
}


#: the Touch bridge's counts (rad), what --velocity-noise is told
TOUCH_COUNTS = load_node_params(CONFIG / "bridge_touch.yaml")["bridge_node"][
    "state.encoder_resolution"
]


def premise(path: str, rate_hz: float) -> list[float]:
    """Skip unless the composed loop with its recorder fits real time at ``rate_hz`` (DOB: the
    observer on the command's path) and the bridge's ``path`` (``PATH_HOPS``) fits a period with
    this machine's raw hop; the hop measured now."""
    require_realtime([SLIDE_LOOP], "DOB", record=True)
    hops = [hop_floor_us()]
    require_path_latency(path, hops[0], rate_hz)
    return hops


def session(
    tmp: Path, name: str, driver: dict[str, Any], config: str, args: list[str]
) -> tuple[Truth, dict[str, Any], Path]:
    """The driver and ``haptic-launch config --namespace /haptic ARGS --record`` until the
    bridge's ``duration_s``, the loop in real time where this machine allows it
    (``scheduling``); the driver's truth, the bridge's counts and the bag."""
    bag = tmp / f"{name}_bag"
    # a Python test driver beside a CPU hog stalls for more than 10 ms now and then (BridgeRun)
    sets = ["bridge_node:state.timeout_s=0.05"]
    extra = [*args, *scheduling.launch_args(), "--record", str(bag)]
    truth, counts = bridge_session(CONFIG / config, driver, tmp / name, sets, extra)
    return truth, counts, bag


def kept_real_time(
    truth: Truth, counts: dict[str, Any], rate_hz: float, presumed: float = CHAIN_ON_TIME
) -> str:
    """Skip when the test driver did not hold its rate (its own premise: a real driver does);
    else '' when ``presumed`` of the commands reached it before its next state, or why not (the
    figures were measured down to that share: the test measures on and skips at the end with
    its figures). No command refused."""
    share = truth.ticked_share()
    if share < DRIVER_SHARE:
        pytest.skip(
            f"the test driver ticked {100 * share:.0f} % of its periods at {rate_hz:g} Hz on "
            f"this machine now (needs {100 * DRIVER_SHARE:.0f} %)"
        )
    assert counts["refused_commands"] == 0, counts
    c = truth.counts
    on_time = c["commands_on_time"] / max(1, c["commands_on_time"] + c["commands_late"])
    if on_time >= presumed:
        return ""
    return (
        f"{100 * on_time:.1f} % of the commands reached the test driver before its next state "
        f"at {rate_hz:g} Hz on this machine now, {scheduling.described()} (the chain "
        f"presumes {100 * presumed:g} %; the driver's states went out "
        f"{c.get('state_out_late_p50_ms', math.nan):.2f} ms after their instants, p99 "
        f"{c.get('state_out_late_p99_ms', math.nan):.2f} ms, of a {1e3 / rate_hz:g} ms period)"
    )


class Figures:
    """What a chain measured, said by a skip when its real-time premise did not hold."""

    def __init__(self) -> None:
        self.missed: list[str] = []
        self.said: list[str] = []

    def premise(self, why: str) -> None:
        if why:
            self.missed.append(why)

    def check(self, ok: bool, figure: str) -> None:
        """Assert ``ok`` where the premise held; else keep ``figure`` for the skip."""
        self.said.append(figure)
        if not self.missed:
            assert ok, "; ".join(self.said)

    def end(self) -> None:
        """Skip with the figures when the premise did not hold."""
        if self.missed:
            pytest.skip(f"{'; '.join(self.missed)}; measured anyway: {'; '.join(self.said)}")


def identify(bag: Path, tmp: Path, args: list[str], figures: Figures) -> tuple[Path, Any]:
    """``haptic-identify BAG ARGS --json --write-yaml``: the model file and the fit."""
    model = tmp / "model.yaml"
    argv = [tool("haptic-identify"), str(bag), *args, "--json", "--write-yaml", str(model)]
    cli = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    if cli.returncode != 0:
        figures.check(False, cli.stderr.strip())
        figures.end()
    return model, json.loads(cli.stdout)


def estimate_error(truth: Truth, bag: Path, config: str) -> tuple[float, float]:
    """The estimate's RMS 3-D error over the true hand force's span along the wall's normal, in
    contact (the plant's tip inside the config's wall) from ``SETTLE_S`` on, matched by stamp;
    with a Touch's hand (``Truth.hand_start_ns``) to ``DOB_S`` of its time, else from the first
    estimate to the end (NaN where the window is empty). Also the share of that window's
    states with an estimate in the bag."""
    with open_bag(bag) as reader:
        conns = [c for c in reader.connections if c.topic == "/haptic/wrench_estimate"]
        datas = [data for _, _, data in reader.messages(connections=conns)]
    stamps, est = decode_vectors(datas, WRENCH, (0, 1, 2))
    idx = np.searchsorted(truth.stamps, stamps)
    found = (idx < len(truth.stamps)) & (
        truth.stamps[np.minimum(idx, len(truth.stamps) - 1)] == stamps
    )
    idx, est = idx[found], est[found]
    assert len(idx) >= 0.9 * DOB_S * float(truth.info["rate_hz"]) * 0.5
    wall = build(VirtualWall, node_view(load_node_params(CONFIG / config), "environment_node"))
    normal = np.asarray(wall.normal)
    hand_time = truth.hand_start_ns >= 0
    t = (truth.stamps[idx] - (truth.hand_start_ns if hand_time else truth.stamps[idx[0]])) * 1e-9
    window = (t >= SETTLE_S) & (t < (DOB_S if hand_time else np.inf))
    covered = float(window.sum() / ((DOB_S - SETTLE_S) * float(truth.info["rate_hz"])))
    if not window.any():
        return math.nan, covered
    contact = ((truth.tip[idx] - np.asarray(wall.position)) @ normal > 0.0) & window
    assert contact.sum() >= 0.8 * window.sum(), "the hand did not hold the wall"
    hand = truth.hand[idx][contact]
    err = np.linalg.norm(est[contact] - hand, axis=1)
    return float(np.sqrt(np.mean(err**2)) / np.ptp(hand @ normal)), covered


def test_forcedimension_chain_through_the_bridge(tmp_path: Path) -> None:
    """Excite, record, identify every axis, then DOB with that model, the hand pushing +x into
    the 800 N/m wall: issue 31's figures against the driver's hidden point mass."""
    hops = premise("fd", 1000.0)
    figures = Figures()
    config = "bridge_forcedimension.yaml"
    excite = ["--params", str(CONFIG / "excite" / "forcedimension.yaml")]
    driver: dict[str, Any] = {"kind": "fd", "rate_hz": 1000.0}
    truth, counts, bag = session(tmp_path, "excite", driver, config, excite)
    figures.premise(kept_real_time(truth, counts, 1000.0))
    model, fit = identify(bag, tmp_path, ["--axes", "fd_x,fd_y,fd_z"], figures)
    plant = truth.info["plant"]["cartesian"]
    for i, axis in enumerate(fit["axes"]):
        m = axis["mass_kg"] / plant["mass_kg"][i] - 1.0
        c = axis["viscous_n_s_per_m"] / plant["viscous_n_s_per_m"][i] - 1.0
        name = axis["joint"]
        figures.check(abs(m) <= 0.05, f"{name} mass {100 * m:+.1f} %")
        figures.check(abs(c) <= 0.10, f"{name} viscous {100 * c:+.1f} %")
    driver.update(hand=SLIDE_HAND, hand_direction=[1, 0, 0])
    dob = ["--params", str(model), "--set", "controller_node:mode=DOB"]
    dob += ["--set", f"bridge_node:duration_s={DOB_S}"]
    truth, counts, bag = session(tmp_path, "dob", driver, config, dob)
    hops.append(hop_floor_us())
    require_path_latency("fd", max(hops))
    figures.premise(kept_real_time(truth, counts, 1000.0))
    error, _ = estimate_error(truth, bag, config)
    figures.check(error <= 0.05, f"estimate {100 * error:.1f} % of the span")
    figures.end()


def test_touch_chain_through_the_bridge(tmp_path: Path) -> None:
    """Excite, record, identify the arm's whole model (``--inertial --write-urdf``), then DOB on
    that URDF and the Kalman velocity filter identified from an OL session, the hand pushing the
    stylus down onto the 400 N/m floor: the payload found (the elbow's and shoulder's gravity
    torque within 5 % of the plant's at the start), the Coulomb friction within 20 % and the
    viscous within 10 %, and the estimate within 5 %."""
    hops = premise("touch", 500.0)
    figures = Figures()
    config = "bridge_touch.yaml"
    excite = ["--params", str(CONFIG / "excite" / "touch.yaml")]
    driver: dict[str, Any] = {"kind": "touch", "rate_hz": 500.0, "hand_direction": [0, 0, -1]}
    truth, counts, bag = session(tmp_path, "excite", {**driver, "inkwell": True}, config, excite)
    figures.premise(kept_real_time(truth, counts, 500.0, TOUCH_ON_TIME))
    urdf = tmp_path / "touch.urdf"
    argv = [tool("haptic-identify"), str(bag), "--urdf", "urdf/phantom_omni.urdf"]
    argv += ["--tip-frame", "tip", "--inertial", "--write-urdf", str(urdf)]
    cli = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    if cli.returncode != 0:
        figures.check(False, cli.stderr.strip())
        figures.end()
    plant = truth.info["plant"]
    found = UrdfModel(str(urdf), "tip")
    real = UrdfModel(CONFIG / "urdf" / "phantom_omni.urdf", "tip", payload_kg=plant["payload_kg"])
    start, rest = np.array([0.0, 0.3, 0.2]), np.zeros(3)
    G = found.inverse_dynamics(start, rest, rest)[1:] / real.inverse_dynamics(start, rest, rest)[1:]
    figures.check(bool(np.all(abs(G - 1.0) <= 0.05)), f"gravity torque x{G.round(3)}")
    coulomb = found.coulomb / np.array(plant["coulomb_n_m"]) - 1.0
    figures.check(bool(np.all(abs(coulomb) <= 0.20)), f"Coulomb {np.round(100 * coulomb)} %")
    viscous = found.viscous / np.array(plant["viscous_n_m_s_per_rad"]) - 1.0
    figures.check(bool(np.all(abs(viscous) <= 0.10)), f"viscous {np.round(100 * viscous)} %")
    ol = ["--set", f"bridge_node:duration_s={DOB_S + PRESS_S}"]  # the hand moves from the press
    hand = {**driver, "hand": TOUCH_HAND}
    truth, counts, bag = session(tmp_path, "ol", {**hand, "seed": 1}, config, ol)
    figures.premise(kept_real_time(truth, counts, 500.0, TOUCH_ON_TIME))
    velocity = tmp_path / "velocity.yaml"
    argv = [tool("haptic-identify"), str(bag), "--velocity-noise", "--write-yaml", str(velocity)]
    argv += ["--counts", ",".join(f"{c:g}" for c in TOUCH_COUNTS)]
    cli = subprocess.run(argv, capture_output=True, text=True, timeout=300)
    if cli.returncode != 0:
        figures.check(False, cli.stderr.strip())
        figures.end()
    dob = [f"{n}:urdf_path={urdf}" for n in ("bridge_node", "observer_node", "controller_node")]
    dob = [a for s in dob for a in ("--set", s)] + ["--set", "controller_node:mode=DOB"]
    dob += ["--params", str(velocity), "--set", f"bridge_node:duration_s={DOB_S + PRESS_S}"]
    truth, counts, bag = session(tmp_path, "dob", hand, config, dob)
    hops.append(hop_floor_us())
    require_path_latency("touch", max(hops), 500.0)
    figures.premise(kept_real_time(truth, counts, 500.0, TOUCH_ON_TIME))
    error, covered = estimate_error(truth, bag, config)
    ran_s = (truth.stamps[truth.published][-1] - truth.hand_start_ns) * 1e-9
    if ran_s < DOB_S:
        figures.premise(
            f"the session ended {ran_s:.1f} s into the hand's time, not {DOB_S:g} s "
            "(the press was heard late)"
        )
    elif covered < 0.9:
        figures.premise(
            f"{100 * covered:.0f} % of the states of the hand's time from {SETTLE_S:g} to "
            f"{DOB_S:g} s have an estimate in the bag (states or estimates lost)"
        )
    figures.check(error <= 0.05, f"estimate {100 * error:.2f} % of the span")
    figures.end()
