"""How fast this machine turns the loop over, measured by the suite itself (once per layout).

A test whose premise is real time at 1 kHz (the device ticking on the wall clock, commands due
before the next tick) can only hold on a machine that turns the same loop over, in the same
process layout, well inside a period. The measurement is a short lockstep run of that layout:
its real-time factor is how many periods of loop work fit in one period of wall time. Below
``REQUIRED_RTF`` such a test skips, saying the figure; every other test runs whatever the machine.
A loop across processes also waits on DDS between them, however little work its nodes do: the
raw hop (``haptic_dob.runtime.ros.dds_hop``) times the hops on the command's path must fit in
``HOPS_SHARE`` of a period, or the test skips, saying that figure.
"""

from __future__ import annotations

import re
import subprocess
from collections.abc import Mapping, Sequence

import pytest

from haptic_dob.runtime.ros.dds_hop import hop_us
from support.paths import BIN, ROOT
from support.rosgraph import Collector, isolated_env, random_domain

#: the loop work of a cycle must fit in 5/6 of a period: a sixth of it left for the jitter of a
#: loaded machine (the device's watchdog zeroes the force after five late periods)
REQUIRED_RTF = 1.2
MEASURE_S = 2.0  # simulated seconds of the lockstep measurement
PROBE_TIMEOUT_S = 200  # wall seconds the probe may take (the tests' own timeout is 300 s)

#: the raw DDS hops between processes on a real-time loop's path may take at most this share of a
#: period: the rest is the device's tick (its wake-up, the plant step, its publishing), the nodes'
#: work and a loaded machine's jitter. Four processes on two cores turn the command around in
#: 1.1-1.5x the floor of three hops (median latencies) and miss the next tick on about half the
#: cycles once that median passes 0.75 of a period; one hop's median changes by up to 2x from
#: one second to the next on a virtual machine, hence the slower of two measurements
#: (BENCHMARKS.md)
HOPS_SHARE = 0.5
HOP_MESSAGES = 2000  # round trips of one hop measurement (about 1 s)

_measured: dict[tuple[tuple[str, ...], ...], float] = {}


def lockstep_rtf(
    groups: Sequence[Sequence[str]],
    mode: str = "OL",
    sets: Sequence[str] = (),
    watched: Mapping[str, str] | None = None,
) -> float:
    """The lockstep real-time factor of the slide loop with ``groups`` sharing processes (nodes
    in no group alone; ``[]``: four processes), in ``mode``, with ``sets`` (``haptic-launch
    --set``), and with this process watching the ``watched`` topics (topic -> type) as the
    calling test will (a ``rosgraph.Collector``: its CPU is the test's load beside the loop,
    which on one core the loop shares); measured once per layout."""
    key = (*(tuple(sorted(g)) for g in groups), (mode, *sets), tuple(sorted(watched or {})))
    if key not in _measured:
        argv = [str(BIN / "haptic-launch"), str(ROOT / "config" / "slide_sim.yaml")]
        argv += [a for g in groups for a in ("--group", ",".join(g))] or ["--processes"]
        argv += ["--set", f"device_node:duration_s={MEASURE_S}"]
        argv += ["--set", f"controller_node:mode={mode}", "--set", "controller_node:kf=1.0"]
        argv += [a for s in sets for a in ("--set", s)]
        _measured[key] = _probe(argv, {"": watched} if watched else None)
    return _measured[key]


def teleop_lockstep_rtf(
    composed: bool = True, watched: Mapping[str, Mapping[str, str]] | None = None
) -> float:
    """The lockstep real-time factor of the teleoperation graph, the slower device's, each
    channel end using what has come as in real time (so that each side runs at its own pace),
    with this process watching ``watched`` (namespace -> topic -> type) as the calling test will;
    measured once per layout: ``composed`` every node in one process, else a process per side
    (real time's default)."""
    watching = tuple(f"{ns}/{t}" for ns, topics in sorted((watched or {}).items()) for t in topics)
    key = (("teleop_sim", "composed" if composed else "sides"), watching)
    if key not in _measured:
        argv = [str(BIN / "haptic-launch"), str(ROOT / "config" / "teleop_sim.yaml")]
        argv += ["--composed"] if composed else ["--group", "master", "--group", "slave"]
        argv += ["--set", "**/channel_node:wait_for_peer=false"]
        argv += ["--set", f"**/device_node:duration_s={MEASURE_S}"]
        _measured[key] = _probe(argv, watched)
    return _measured[key]


def _probe(argv: list[str], watched: Mapping[str, Mapping[str, str]] | None = None) -> float:
    """Run a lockstep launch, with collectors of ``watched`` (namespace -> topic -> type) in
    this process while it runs; the lowest real-time factor its devices report."""
    env = isolated_env()
    # no back pressure: the devices do not wait for them (as in real time), their CPU is the load
    cols = [
        Collector(env, dict(topics), name=f"probe_{i}", namespace=ns, back_pressure=False)
        for i, (ns, topics) in enumerate(sorted((watched or {}).items()))
    ]
    # inside the test's own timeout, so a stuck probe says what it printed; SIGTERM lets
    # haptic-launch stop the nodes it started (a SIGKILL would orphan them)
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True
    )
    try:
        stdout, stderr = proc.communicate(timeout=PROBE_TIMEOUT_S)
    except subprocess.TimeoutExpired:
        proc.terminate()
        stdout, stderr = proc.communicate(timeout=60)
        pytest.fail(f"the capacity probe ran over {PROBE_TIMEOUT_S} s:\n{stderr[-2000:]}")
    finally:
        for col in reversed(cols):
            col.close()
    found = re.findall(r"real-time factor ([0-9.]+)", stderr + stdout)
    assert proc.returncode == 0 and found, stderr[-2000:]
    return min(float(f) for f in found)


def require_realtime(
    groups: Sequence[Sequence[str]],
    mode: str = "OL",
    sets: Sequence[str] = (),
    watched: Mapping[str, str] | None = None,
) -> float:
    """Skip the calling test unless this machine turns this layout over at ``REQUIRED_RTF`` times
    real time or faster (now, under whatever else runs, with the test watching ``watched``);
    returns the figure."""
    rtf = lockstep_rtf(groups, mode, sets, watched)
    if rtf < REQUIRED_RTF:
        layout = " | ".join(", ".join(g) for g in groups) or "four processes"
        watching = f", this test watching {len(watched)} topics" if watched else ""
        pytest.skip(
            f"this machine turns the loop ({layout}; {mode}{watching}) over at {rtf:.2f}x real "
            f"time in lockstep, measured now; real time at 1 kHz needs {REQUIRED_RTF:g}x"
        )
    return rtf


def require_realtime_teleop(
    composed: bool = True, watched: Mapping[str, Mapping[str, str]] | None = None
) -> float:
    """Skip the calling test unless this machine turns the teleoperation graph in that layout
    (``teleop_lockstep_rtf``, with the test watching ``watched``) over at ``REQUIRED_RTF`` times
    real time or faster in lockstep (now); returns the slower side's figure."""
    rtf = teleop_lockstep_rtf(composed, watched)
    if rtf < REQUIRED_RTF:
        layout = "all in one process" if composed else "a process per side"
        if watched:
            layout += f", this test watching {sum(len(t) for t in watched.values())} topics"
        pytest.skip(
            f"this machine turns the teleoperation graph ({layout}) over at {rtf:.2f}x real time "
            f"in lockstep (the slower side), measured now; real time at 1 kHz needs "
            f"{REQUIRED_RTF:g}x"
        )
    return rtf


def hop_floor_us() -> float:
    """One raw DDS hop between two processes, now (µs, median one-way; ``dds_hop.hop_us``) on a
    domain id of this test's own."""
    return hop_us(HOP_MESSAGES, domain_id=random_domain())


def require_hop_floor(hops: int, hop_us_now: float, rate_hz: float = 1000.0) -> None:
    """Skip the calling test unless ``hops`` raw DDS hops of ``hop_us_now`` (µs, the slower of
    the measurements around the run) fit in ``HOPS_SHARE`` of a period at ``rate_hz``: past
    that, no loop across those processes holds the rate on this machine now, whatever its
    nodes do."""
    floor_us = hops * hop_us_now
    budget_us = HOPS_SHARE * 1e6 / rate_hz
    if floor_us > budget_us:
        pytest.skip(
            f"{hops} raw DDS hops between processes take {floor_us:.0f} us on this machine, "
            f"measured now ({hop_us_now:.0f} us each); a real-time loop at {rate_hz:g} Hz "
            f"across them needs at most {budget_us:.0f} us"
        )
