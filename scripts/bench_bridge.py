"""The device bridge's latency: a test driver's state to its command, against the raw DDS hop.

Each run starts a test driver (``test/support/drivers``, ``PROFILES``: Force Dimension-like at
1 kHz, Touch-like at 500 Hz with the stylus button held, a Franka-like arm at 1 kHz as a
teleoperation slave) and ``haptic-launch`` of its config for ``RUN_S`` seconds on a fresh domain
id, one raw hop (``dds_hop``) measured before and after, and after it the raw answer's on-time
share at the driver's rate (``answer_floor``: no work, the same scheduling). The driver measures
from publishing state k to its first answer, whether command k came before state k+1's instant
(on time) and whether the first answer came within a period of state k going out (what a driver
that publishes at its instant gets: the Python driver is late at times, by the p99 given). The
latency's median is set against the slower raw hop (floor: two hops), the on-time share against
the raw answer's. ``GRAPH_ARGS`` go to ``haptic-launch``; with ``--rt-priority P`` the driver
runs under SCHED_FIFO P too, as a controller manager runs. ``CPUS`` (``--cpus LIST``): the
driver, the loop and the floor under ``taskset -c LIST`` (``timer-floor``; docs/running.md).
"""

from __future__ import annotations

import argparse
import json
import os
import random
import signal
import statistics
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import cast

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "test"))  # the test drivers live with the tests

from bench_graph import GRAPH_ARGS, graph_option, graph_sched  # noqa: E402
from haptic_dob.runtime.ros.answer_floor import answer_floor  # noqa: E402
from haptic_dob.runtime.ros.dds_hop import hop_us  # noqa: E402
from support.drivers.run import SLIDE_HAND, Controls, Truth, start  # noqa: E402

RUN_S = 10.0
#: ``taskset -c`` CPU list of the driver and the loop (``--cpus``); empty: the process's CPUs
CPUS: list[str] = []
#: the profiles to run (``--profiles``); empty: every one of ``PROFILES``
ONLY: list[str] = []
#: name -> (config, the test driver, the bridge node's name in the launch, haptic-launch's extra)
PROFILES: dict[str, tuple[str, dict[str, object], str, list[str]]] = {
    "fd": (
        "bridge_forcedimension.yaml",
        {"kind": "fd", "rate_hz": 1000.0, "hand": SLIDE_HAND, "hand_direction": [1, 0, 0]},
        "bridge_node",
        ["--namespace", "/haptic"],
    ),
    "touch": (
        "bridge_touch.yaml",
        {
            "kind": "touch",
            "rate_hz": 500.0,
            "hand": {**SLIDE_HAND, "offset_m": 0.012},
            "hand_direction": [0, 0, -1],
        },
        "bridge_node",
        ["--namespace", "/haptic"],
    ),
    "arm": (  # a Franka-like ros2_control arm as the slave of the simulated slide (teleoperation)
        "bridge_arm_teleop.yaml",
        {"kind": "arm", "rate_hz": 1000.0, "table_z": 0.39},
        "slave/bridge_node",
        ["--robot-description", "/arm/robot_description"],
    ),
}


def cpus_prefix() -> list[str]:
    """``taskset -c LIST`` when ``CPUS`` names CPUs, else nothing."""
    return ["taskset", "-c", CPUS[0]] if CPUS else []


def driver_priority() -> int:
    """The driver's SCHED_FIFO priority: the graph's ``--rt-priority P``, else 0 (none)."""
    return graph_option("--rt-priority") or 0


def stop_group(proc: subprocess.Popen[bytes]) -> None:
    """Stop ``proc``'s process group if ``proc`` still runs (a run that timed out or failed):
    SIGINT, as a user's Ctrl-C, then SIGKILL after ``haptic-launch``'s stop timeout."""
    if proc.poll() is not None:
        return
    os.killpg(proc.pid, signal.SIGINT)
    try:
        proc.wait(timeout=15.0)
    except subprocess.TimeoutExpired:
        os.killpg(proc.pid, signal.SIGKILL)
        proc.wait()


def one_run(profile: str) -> dict[str, float]:
    """One session of ``profile``: the driver's counts, the bridge's, the raw hops around it
    and the raw answer's floor after it."""
    config, driver, bridge_name, extra = PROFILES[profile]
    domain = random.randint(101, 200)
    env = dict(os.environ, ROS_DOMAIN_ID=str(domain), ROS_AUTOMATIC_DISCOVERY_RANGE="LOCALHOST")
    hop_before = hop_us(2000, domain_id=domain)
    with tempfile.TemporaryDirectory(prefix="bench-bridge-") as tmp:
        d = Path(tmp)
        drv = start({**driver, "rt_priority": driver_priority()}, env, d / "driver", cpus_prefix())
        controls = Controls(env, "/touch") if profile == "touch" else None
        launch = str(Path(sys.executable).parent / "haptic-launch")
        argv = [*cpus_prefix(), launch, str(ROOT / "config" / config)]
        argv += [*extra, "--set", f"{bridge_name}:duration_s={RUN_S}"]
        argv += ["--set", f"{bridge_name}:stats_file={d / 'bridge.json'}"]
        argv += [a for a in GRAPH_ARGS if a != "--pin"]  # one process: nothing to pin
        log = d / "launch.log"
        with log.open("wb") as sink:
            graph = subprocess.Popen(
                argv,
                env=env,
                stdout=sink,
                stderr=subprocess.STDOUT,
                start_new_session=True,  # its own group: a run that hangs is stopped whole
            )

        def output() -> str:
            return log.read_text(errors="replace")

        try:
            if controls is not None:  # once the loop is up, the user holds the stylus's button
                controls.hold(output)  # the driver's hand moves from the press the bridge heard
            graph.wait(timeout=RUN_S + 120)
        finally:
            stop_group(graph)
            if controls is not None:
                controls.close()
            drv.stop()
        if graph.returncode != 0:
            raise RuntimeError(f"haptic-launch failed: {output()[-1500:]}")
        truth = Truth.read(d / "driver")
        bridge = json.loads((d / "bridge.json").read_text())
    hop_after = hop_us(2000, domain_id=domain)
    cpus = {int(c) for c in CPUS[0].split(",")} if CPUS else None
    floor = answer_floor(
        cast(float, driver["rate_hz"]), RUN_S, sched=graph_sched(), domain_id=domain, cpus=cpus
    )
    c = truth.counts
    return {
        "hop_us": max(hop_before, hop_after),
        "latency_p50_us": c["latency_p50_ms"] * 1e3,
        "latency_p99_us": c["latency_p99_ms"] * 1e3,
        "on_time_pct": 100.0 * c["commands_on_time"] / (c["commands_on_time"] + c["commands_late"]),
        "raw_on_time_pct": floor.on_time_pct,
        "within_pct": 100.0 * c["commands_within_period"] / max(1, c["states_answered_span"]),
        "bridge_p50_us": bridge["latency_p50_ms"] * 1e3,
        "ticked_pct": 100.0 * truth.ticked_share(),
        "tick_late_p99_us": c["tick_late_p99_ms"] * 1e3,
        "out_late_p50_us": c["state_out_late_p50_ms"] * 1e3,
    }


def bench_bridge(repeat: int) -> str:
    """Driver state -> command latency through the bridge (composed) against one raw hop."""
    parts = []
    for profile in ONLY or PROFILES:
        runs = [one_run(profile) for _ in range(repeat)]
        med = {k: statistics.median(r[k] for r in runs) for k in runs[0]}
        ratio = [r["latency_p50_us"] / r["hop_us"] for r in runs]
        on_time = ", ".join(f"{r['on_time_pct']:.2f}" for r in runs)
        raw = ", ".join(f"{r['raw_on_time_pct']:.2f}" for r in runs)
        ticked = ", ".join(f"{r['ticked_pct']:.0f}" for r in runs)
        within = ", ".join(f"{r['within_pct']:.2f}" for r in runs)
        parts.append(
            f"{profile}: state->command p50 {med['latency_p50_us']:.0f} us "
            f"(p99 {med['latency_p99_us']:.0f}), {statistics.median(ratio):.1f}x one raw hop "
            f"({med['hop_us']:.0f} us; floor 2x), inside the bridge {med['bridge_p50_us']:.0f} "
            f"us; on time {on_time} % (raw answers {raw} %); within a period of the state "
            f"{within} %; driver ticked "
            f"{ticked} % of its periods, p99 {med['tick_late_p99_us']:.0f} us after its instant, "
            f"its states out p50 {med['out_late_p50_us']:.0f} us after their instants"
        )
    return "; ".join(parts)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(
        description="The device bridge's driver-state -> command latency against one raw hop.",
        epilog="scripts/benchmarks.py bridge runs it with --rt-priority, --cpu-latency, --cpus.",
    )
    parser.add_argument("repeat", nargs="?", type=int, default=1, help="runs per profile (>= 1)")
    args = parser.parse_args()
    if args.repeat < 1:
        parser.error(f"repeat {args.repeat}: must be 1 or more")
    print(bench_bridge(args.repeat))
