"""Run-time switching of the law through the parameter service, on a live lockstep graph."""

from __future__ import annotations

import itertools
import re
import time

import numpy as np
import pytest

from haptic_msgs_py.convert import read_force
from haptic_msgs_py.stamps import command_stamp, stamp_ns
from haptic_msgs_py.topics import (
    EFFORT_COMMAND,
    HAND_WRENCH,
    SESSION_TOPICS,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)
from rosgraph import Collector, isolated_env, launch, set_parameter

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

WAIT_FOR = "device_node:wait_for=[environment_node, observer_node, controller_node, collector]"
TOPICS = {
    t: SESSION_TOPICS[t]
    for t in (EFFORT_COMMAND, WRENCH_DESIRED, WRENCH_MEASURED, WRENCH_ESTIMATE, HAND_WRENCH)
}


def laws(col: Collector, kf: float, start: str = "OL") -> tuple[list[int], list[str]]:
    """For each command: its stamp and which law produced it (OL, CL, DOB or '?').

    Where several laws give the same command (no contact: all zero) the command is given to the
    law in force before it (``start`` for the first), if that is one of them.
    """
    by_stamp = {
        t: {stamp_ns(m): read_force(m)[0] for m in col.messages(t)}
        for t in (WRENCH_DESIRED, WRENCH_MEASURED, WRENCH_ESTIMATE)
    }
    stamps, which = [], []
    for c in col.messages(EFFORT_COMMAND):
        k = command_stamp(c.layout.dim[0].label)
        if k not in by_stamp[WRENCH_DESIRED]:
            continue  # the collector's subscription matched after this cycle
        fw = by_stamp[WRENCH_DESIRED][k]
        u = c.data[0]
        candidates = {"OL": fw}
        if k in by_stamp[WRENCH_MEASURED]:
            candidates["CL"] = fw + kf * (fw + by_stamp[WRENCH_MEASURED][k])
        if k in by_stamp[WRENCH_ESTIMATE]:
            candidates["DOB"] = fw + kf * (fw + by_stamp[WRENCH_ESTIMATE][k])
        match = [n for n, v in candidates.items() if abs(np.clip(v, -4, 4) - u) < 1e-12]
        stamps.append(k)
        before = which[-1] if which else start
        if len(match) > 1 and before in match:
            match = [before]
        which.append(match[0] if len(match) == 1 else "?" if not match else "+".join(match))
    return stamps, which


def test_switch_ol_dob_cl_takes_effect_on_the_next_cycle(root, tmp_path) -> None:
    env = isolated_env()
    col = Collector(env, TOPICS)
    sets = [WAIT_FOR, "device_node:duration_s=0.0", "controller_node:kf=1.0"]
    graph = launch(str(root / "config" / "slide_sim.yaml"), env, sets, tmp_path / "launch.log")
    switched_at: dict[str, float] = {}
    try:
        assert col.wait_for(EFFORT_COMMAND, 1500, 60), graph.output()
        ok, reason = set_parameter(env, "controller_node", "mode", "DOB")
        switched_at["DOB"] = time.monotonic()
        assert ok, reason
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 1000, 30)
        ok, reason = set_parameter(env, "controller_node", "kf", -1.0)
        assert not ok and "kf" in reason and "range" in reason
        ok, reason = set_parameter(env, "controller_node", "mode", "PID")
        assert not ok and "mode must be one of OL, CL, DOB" in reason
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 500, 30)
        ok, reason = set_parameter(env, "controller_node", "mode", "CL")
        switched_at["CL"] = time.monotonic()
        assert ok, reason
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 1000, 30)
    finally:
        graph.stop()
        col.close()
    stamps, which = laws(col, kf=1.0)
    assert "?" not in which, "every command is one of the three laws"
    # one clean switch each: OL...OL DOB...DOB CL...CL
    runs = [which[0]] + [b for a, b in itertools.pairwise(which) if a != b]
    assert runs == ["OL", "DOB", "CL"]
    assert stamps == sorted(stamps)
    # "the next cycle": the controller names the last cycle of the old law; the new law's first
    # command is for the cycle right after it
    log = graph.output()
    for law in switched_at:
        match = re.search(rf"law now {law}, .* after stamp_ns (\d+)", log)
        assert match, log
        last_old = int(match.group(1))
        first_new = stamps[which.index(law)]
        assert first_new == last_old + 1_000_000
        assert all(w != law for k, w in zip(stamps, which, strict=True) if k <= last_old)
