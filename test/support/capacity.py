"""Whether this machine can carry a loop in real time, measured by the suite itself (once per
layout): the CPU a cycle costs, against the CPU a period gives, and the DDS floor of its path.

The measurement is a short lockstep run of the test's layout (the same processes, nodes and
topics): the CPU time (user + system, ``/proc``) its processes spend per cycle, which is what a
cycle costs in real time too. It holds when

- the cycle's CPU across the loop's processes and the test's watchers fits in ``CPU_SHARE`` of
  the free CPUs of the run's affinity (less what other processes kept busy, ``/proc/stat``)
  times the period;
- the busiest process's fits in ``CPU_SHARE`` of one period (one spin thread each);
- the raw DDS hops on the command's path (``haptic_dob.runtime.ros.dds_hop``) fit in
  ``HOPS_SHARE`` of a period.

Otherwise the test skips, saying the figures."""

from __future__ import annotations

import os
import re
import subprocess
import tempfile
import threading
import time
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from itertools import pairwise
from pathlib import Path

import pytest

from haptic_dob.runtime.ros.dds_hop import hop_us
from support.paths import BIN, ROOT
from support.rosgraph import Collector, isolated_env, random_domain

#: the loop's CPU of a cycle must fit in this share of what a period gives: the rest is the
#: jitter of a loaded machine and the wake-ups that lockstep does not have (the device's tick)
CPU_SHARE = 0.8
MEASURE_S = 2.0  # simulated seconds of the lockstep measurement
PROBE_TIMEOUT_S = 200  # wall seconds the probe may take (the tests' own timeout is 300 s)
SAMPLE_S = 0.01  # how often the probe reads the processes' CPU times
TICK_S = 1.0 / os.sysconf("SC_CLK_TCK")  # the resolution of /proc/PID/stat's CPU times

#: the raw DDS hops between processes on a real-time loop's path may take at most this share of a
#: period: the rest is the device's tick (its wake-up, the plant step, its publishing), the nodes'
#: work and a loaded machine's jitter: a floor no loop goes under. A test that asserts most
#: commands on time takes its path's measured latency instead (``require_path_latency``). One
#: hop's median changes by up to 2x from one second to the next on a virtual machine, hence the
#: slower of two measurements (BENCHMARKS.md)
HOPS_SHARE = 0.5
HOP_MESSAGES = 2000  # round trips of one hop measurement (about 1 s)

#: a real-time path's median command latency in raw DDS hops, measured on the development
#: machine (BENCHMARKS.md): four processes, OL, as ``test_graph_realtime`` runs it (3.0 times
#: its three hops); the bridge composed with the loop against the Force Dimension-, Touch- and
#: arm-like test drivers (6.7, 9.8 and 8.2 times one hop, 617db16). The ratio holds on a slower
#: machine (one with a 150 us hop put four processes' median past a period: 42 % on time)
PATH_HOPS = {"processes": 9.0, "fd": 6.7, "touch": 9.8, "arm": 8.2}
#: a path's median latency may take this share of a period: past it, about half the commands
#: miss the next tick
LATENCY_SHARE = 0.75

#: the command's paths through the loop's nodes (OL and CL: the wall; DOB: the observer too)
PATHS = {
    "OL": (("device_node", "environment_node", "controller_node", "device_node"),),
    "DOB": (
        ("device_node", "environment_node", "controller_node", "device_node"),
        ("device_node", "observer_node", "controller_node", "device_node"),
    ),
}


@dataclass(frozen=True)
class CycleCost:
    """What a cycle of a layout costs this machine now (µs of CPU) and what it has."""

    total_us: float  # CPU of a cycle across the loop's processes and this test's watchers
    busiest_us: float  # the busiest process's
    processes: int  # the loop's processes
    cpus: int  # the CPUs of the run's affinity
    others: float  # CPUs of those that other processes kept busy during the measurement
    period_us: float

    @property
    def free(self) -> float:
        """The CPUs the run may use: its affinity's, less what others kept busy."""
        return max(0.0, self.cpus - self.others)

    def fits(self) -> bool:
        """The cycle's CPU fits in ``CPU_SHARE`` of the free CPUs' period, the busiest
        process's in ``CPU_SHARE`` of one period."""
        return (
            self.total_us <= CPU_SHARE * self.free * self.period_us
            and self.busiest_us <= CPU_SHARE * self.period_us
        )

    def text(self) -> str:
        """The figures, as a skip says them."""
        return (
            f"a cycle costs {self.total_us:.0f} us of CPU across {self.processes} process(es) "
            f"(the busiest {self.busiest_us:.0f} us), measured now in lockstep; real time at "
            f"{1e6 / self.period_us:g} Hz needs at most {CPU_SHARE:g} x {self.free:.2f} free "
            f"CPU(s) ({self.cpus} less {self.others:.2f} that others kept busy) x "
            f"{self.period_us:.0f} us = {CPU_SHARE * self.free * self.period_us:.0f} us "
            f"(the busiest at most {CPU_SHARE * self.period_us:.0f} us)"
        )


_measured: dict[tuple[tuple[str, ...], ...], CycleCost] = {}


def cycle_cost(
    groups: Sequence[Sequence[str]],
    mode: str = "OL",
    sets: Sequence[str] = (),
    watched: Mapping[str, str] | None = None,
    record: bool = False,
) -> CycleCost:
    """The CPU a cycle of the slide loop costs with ``groups`` sharing processes (nodes in no
    group alone; ``[]``: four processes), in ``mode``, with ``sets`` (``haptic-launch --set``),
    with this process watching the ``watched`` topics (topic -> type) as the calling test
    will (a ``rosgraph.Collector``: its CPU counts), and with the session recorded
    (``record``: ``--record``'s recorder, a process of its own); measured once per layout."""
    key = (
        *(tuple(sorted(g)) for g in groups),
        (mode, *sets),
        tuple(sorted(watched or {})),
        ("record",) if record else (),
    )
    if key not in _measured:
        argv = [str(BIN / "haptic-launch"), str(ROOT / "config" / "slide_sim.yaml")]
        argv += [a for g in groups for a in ("--group", ",".join(g))] or ["--processes"]
        argv += ["--set", f"device_node:duration_s={MEASURE_S}"]
        argv += ["--set", f"controller_node:mode={mode}", "--set", "controller_node:kf=1.0"]
        argv += [a for s in sets for a in ("--set", s)]
        with tempfile.TemporaryDirectory(prefix="capacity-") as tmp:
            argv += ["--record", str(Path(tmp) / "bag")] if record else []
            _measured[key] = _probe(argv, {"": watched} if watched else None)
    return _measured[key]


def teleop_cycle_cost(
    composed: bool = True, watched: Mapping[str, Mapping[str, str]] | None = None
) -> CycleCost:
    """The CPU a cycle of the teleoperation graph costs (both sides), each channel end using
    what has come as in real time, with this process watching ``watched`` (namespace -> topic
    -> type) as the calling test will; measured once per layout: ``composed`` every node in one
    process, else a process per side (real time's default)."""
    watching = tuple(f"{ns}/{t}" for ns, topics in sorted((watched or {}).items()) for t in topics)
    key = (("teleop_sim", "composed" if composed else "sides"), watching)
    if key not in _measured:
        argv = [str(BIN / "haptic-launch"), str(ROOT / "config" / "teleop_sim.yaml")]
        argv += ["--composed"] if composed else ["--group", "master", "--group", "slave"]
        argv += ["--set", "**/channel_node:wait_for_peer=false"]
        argv += ["--set", f"**/device_node:duration_s={MEASURE_S}"]
        _measured[key] = _probe(argv, watched)
    return _measured[key]


def _cpu_s(pid: int | str) -> float | None:
    """User + system CPU time (s) of process ``pid`` so far, None once it is gone."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return None
    return (int(fields[11]) + int(fields[12])) * TICK_S  # utime, stime


def _busy_s(cpus: set[int]) -> float:
    """Time (s) the CPUs ``cpus`` spent busy so far, every process's (``/proc/stat``)."""
    busy = 0
    for line in Path("/proc/stat").read_text().splitlines():
        name, *fields = line.split()
        if name.startswith("cpu") and name[3:].isdigit() and int(name[3:]) in cpus:
            user, nice, system, _idle, _iowait, irq, softirq, steal = map(int, fields[:8])
            busy += user + nice + system + irq + softirq + steal
    return busy * TICK_S


def _children(pid: int) -> list[int]:
    """The child processes of ``pid`` (the launcher's nodes; none once it has exited)."""
    out: list[int] = []
    try:
        tasks = list(Path(f"/proc/{pid}/task").iterdir())
    except OSError:  # the launcher ended between two samples
        return out
    for task in tasks:
        try:
            out += [int(c) for c in (task / "children").read_text().split()]
        except OSError:
            continue
    return out


class _Sampler:
    """The CPU times of the launcher's child processes and of this one, read every
    ``SAMPLE_S`` in a thread while the run goes on: (monotonic s, {pid: CPU s})."""

    def __init__(self, launcher: int) -> None:
        self.launcher = launcher
        self.cpus = os.sched_getaffinity(0)
        self.rows: list[tuple[float, dict[int | str, float]]] = []
        self._stop = threading.Event()
        self._thread = threading.Thread(target=self._run, daemon=True)
        self._thread.start()

    def _run(self) -> None:
        while not self._stop.wait(SAMPLE_S):
            row: dict[int | str, float] = {}
            for pid in _children(self.launcher):
                cpu = _cpu_s(pid)
                if cpu is not None:
                    row[pid] = cpu
            own = _cpu_s("self")
            if own is not None:
                row["self"] = own
            row["busy"] = _busy_s(self.cpus)
            self.rows.append((time.monotonic(), row))

    def stop(self) -> None:
        self._stop.set()
        self._thread.join(5)

    def at(self, t: float) -> dict[int | str, float]:
        """The CPU times read last at or before ``t`` (monotonic s)."""
        before = [row for when, row in self.rows if when <= t]
        return before[-1] if before else {}


def _probe(argv: list[str], watched: Mapping[str, Mapping[str, str]] | None = None) -> CycleCost:
    """Run a lockstep launch, with collectors of ``watched`` (namespace -> topic -> type) in
    this process while it runs; the CPU of a cycle from sample 0 to each device's last."""
    env = isolated_env()
    # no back pressure: the devices do not wait for them (as in real time), their CPU is the load
    cols = [
        Collector(env, dict(topics), name=f"probe_{i}", namespace=ns, back_pressure=False)
        for i, (ns, topics) in enumerate(sorted((watched or {}).items()))
    ]
    finished: list[tuple[float, int, float]] = []  # (when said, cycles, wall s since sample 0)
    lines: list[str] = []
    # inside the test's own timeout, so a stuck probe says what it printed; SIGTERM lets
    # haptic-launch stop the nodes it started (a SIGKILL would orphan them)
    proc = subprocess.Popen(
        argv, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, text=True
    )
    sampler = _Sampler(proc.pid)
    # rcutils stamps each line with the system clock: when the device said it, however late the
    # line reaches this process
    pattern = re.compile(
        r"\[(\d+\.\d+)\] \[[^]]*device_node\]: finished: (\d+) cycles .* in ([0-9.]+) s"
    )
    to_monotonic = time.monotonic() - time.time()
    try:
        assert proc.stdout is not None
        t_end = time.monotonic() + PROBE_TIMEOUT_S
        for line in proc.stdout:  # read as said: the time a device finished is when it says so
            lines.append(line)
            found = pattern.search(line)
            if found:
                said, cycles, wall = found.groups()
                finished.append((float(said) + to_monotonic, int(cycles), float(wall)))
            if time.monotonic() > t_end:
                proc.terminate()
                proc.wait(60)
                said = "".join(lines)[-2000:]
                pytest.fail(f"the capacity probe ran over {PROBE_TIMEOUT_S} s:\n{said}")
        proc.wait(60)
    finally:
        sampler.stop()
        for col in reversed(cols):
            col.close()
    assert proc.returncode == 0 and finished, "".join(lines)[-2000:]
    start = min(t - wall for t, _, wall in finished)  # sample 0 of the first device
    end = max(t for t, _, _ in finished)
    cycles = max(n for _, n, _ in finished)
    first, last = sampler.at(start), sampler.at(end)
    spent = {p: last[p] - first.get(p, 0.0) for p in last if p not in ("self", "busy")}
    own = last.get("self", 0.0) - first.get("self", 0.0)
    busy = last.get("busy", 0.0) - first.get("busy", 0.0)
    others = max(0.0, busy - sum(spent.values()) - own) / max(end - start, SAMPLE_S)
    return CycleCost(
        total_us=(sum(spent.values()) + (own if watched else 0.0)) * 1e6 / cycles,
        busiest_us=max(spent.values(), default=0.0) * 1e6 / cycles,
        processes=len(spent),
        cpus=len(sampler.cpus),
        others=others,
        period_us=1e6 / 1000.0,
    )


def path_hops(groups: Sequence[Sequence[str]], mode: str) -> int:
    """Raw DDS hops between processes on the command's slowest path with ``groups`` sharing
    processes (nodes in no group alone)."""
    home = {n: i for i, g in enumerate(groups) for n in g}

    def process(node: str) -> object:
        return home.get(node, node)

    paths = PATHS["DOB" if mode == "DOB" else "OL"]
    return max(sum(process(a) != process(b) for a, b in pairwise(p)) for p in paths)


def require_realtime(
    groups: Sequence[Sequence[str]],
    mode: str = "OL",
    sets: Sequence[str] = (),
    watched: Mapping[str, str] | None = None,
    record: bool = False,
) -> CycleCost:
    """Skip the calling test unless a cycle of this layout (``cycle_cost``, with the test
    watching ``watched``, recorded when ``record``) fits in what this machine's CPUs give a
    period, now, and its DDS hops across processes fit in ``HOPS_SHARE`` of a period; returns
    the cost."""
    cost = cycle_cost(groups, mode, sets, watched, record)
    layout = " | ".join(", ".join(g) for g in groups) or "four processes"
    layout += ", recorded" if record else ""
    if not cost.fits():
        watching = f", this test watching {len(watched)} topics" if watched else ""
        pytest.skip(f"{layout}; {mode}{watching}: {cost.text()}")
    hops = path_hops(groups, mode)
    if hops:
        require_hop_floor(hops, hop_floor_us())
    return cost


def require_realtime_teleop(
    composed: bool = True, watched: Mapping[str, Mapping[str, str]] | None = None
) -> CycleCost:
    """Skip the calling test unless a cycle of the teleoperation graph in that layout
    (``teleop_cycle_cost``, with the test watching ``watched``) fits in what this machine's CPUs
    give a period, now; returns the cost."""
    cost = teleop_cycle_cost(composed, watched)
    if not cost.fits():
        layout = "all in one process" if composed else "a process per side"
        if watched:
            layout += f", this test watching {sum(len(t) for t in watched.values())} topics"
        pytest.skip(f"the teleoperation graph ({layout}): {cost.text()}")
    return cost


def hop_floor_us() -> float:
    """One raw DDS hop between two processes, now (µs, median one-way; ``dds_hop.hop_us``) on a
    domain id of this test's own."""
    return hop_us(HOP_MESSAGES, domain_id=random_domain())


def require_hop_floor(hops: int, hop_us_now: float, rate_hz: float = 1000.0) -> None:
    """Skip the calling test unless ``hops`` raw DDS hops of ``hop_us_now`` (µs, the slower of
    the measurements around the run) fit in ``HOPS_SHARE`` of a period at ``rate_hz``: past
    that, no loop across those processes holds the rate on this machine now, whatever its
    nodes do."""
    _skip_over(
        hops * hop_us_now,
        HOPS_SHARE * 1e6 / rate_hz,
        f"{hops} raw DDS hops between processes take {{:.0f}} us on this machine, measured now "
        f"({hop_us_now:.0f} us each); a real-time loop at {rate_hz:g} Hz across them needs at "
        "most {:.0f} us",
    )


def require_path_latency(path: str, hop_us_now: float, rate_hz: float = 1000.0) -> None:
    """Skip the calling test unless ``path``'s median latency, ``PATH_HOPS[path]`` raw hops of
    ``hop_us_now`` (µs, the slower of the measurements around the run), fits in
    ``LATENCY_SHARE`` of a period at ``rate_hz``: past that, this machine now turns the command
    around after the next tick about half the time, whatever the path's code does."""
    hops = PATH_HOPS[path]
    _skip_over(
        hops * hop_us_now,
        LATENCY_SHARE * 1e6 / rate_hz,
        f"the {path} path's median latency, {hops:g} raw DDS hops on the development machine, "
        f"is {{:.0f}} us with this machine's hop now ({hop_us_now:.0f} us); a real-time loop at "
        f"{rate_hz:g} Hz needs it under {{:.0f}} us",
    )


def _skip_over(us: float, budget_us: float, text: str) -> None:
    """Skip the calling test, saying ``text`` with both figures, when ``us`` passes
    ``budget_us``."""
    if us > budget_us:
        pytest.skip(text.format(us, budget_us))
