"""Run-time switching of the law through the parameter service, on a live lockstep graph."""

from __future__ import annotations

import re
import time

import numpy as np
import pytest

from haptic_msgs_py.stamps import command_stamp, stamp_ns
from haptic_msgs_py.topics import (
    EFFORT_COMMAND,
    HAND_WRENCH,
    SESSION_TOPICS,
    WRENCH_DESIRED,
    WRENCH_ESTIMATE,
    WRENCH_MEASURED,
)
from support.rosgraph import Collector, isolated_env, launch, read_force, set_parameter, switch
from support.waits import wait_until

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

WAIT_FOR = "device_node:wait_for=[environment_node, observer_node, controller_node, collector]"
TOPICS = {
    t: SESSION_TOPICS[t]
    for t in (EFFORT_COMMAND, WRENCH_DESIRED, WRENCH_MEASURED, WRENCH_ESTIMATE, HAND_WRENCH)
}


def laws(
    col: Collector, kf: float
) -> tuple[list[int], list[set[str]], list[tuple[float, dict[str, float]]]]:
    """For each command: its stamp, the laws (OL, CL, DOB) that give exactly that command, and
    (for messages) the command with each law's value.

    Several laws can match one command (out of contact all are zero; at the force limit they
    saturate alike), so a command is checked against the law in force, never guessed.
    """
    by_stamp = {
        t: {stamp_ns(m): read_force(m)[0] for m in col.messages(t)}
        for t in (WRENCH_DESIRED, WRENCH_MEASURED, WRENCH_ESTIMATE)
    }
    stamps, matches, values = [], [], []
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
        stamps.append(k)
        matches.append({n for n, v in candidates.items() if abs(np.clip(v, -4, 4) - u) < 1e-12})
        values.append((u, candidates))
    return stamps, matches, values


def test_switch_ol_dob_cl_takes_effect_on_the_next_cycle(root, tmp_path) -> None:
    env = isolated_env()
    col = Collector(env, TOPICS)
    sets = [WAIT_FOR, "device_node:duration_s=0.0", "controller_node:kf=1.0"]
    graph = launch(str(root / "config" / "slide_sim.yaml"), env, sets, tmp_path / "launch.log")
    switched_at: dict[str, float] = {}
    said: dict[str, str] = {}  # law -> the controller's line naming the old law's last cycle

    def wait_said(law: str) -> None:
        """The evidence is the controller's line: read it while the graph runs (bounded), not
        from whatever of the output is left after the stop."""
        pattern = re.compile(rf"law now {law}, .* after stamp_ns \d+")

        def found() -> bool:
            match = pattern.search(graph.output())
            if match:
                said[law] = match.group(0)
            return match is not None

        assert wait_until(found, 30, poll_s=0.1), graph.output()

    try:
        assert col.wait_for(EFFORT_COMMAND, 1500, 60), graph.output()
        ok, reason = switch(env, "DOB")
        switched_at["DOB"] = time.monotonic()
        assert ok, reason
        wait_said("DOB")
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 1000, 30)
        ok, reason = set_parameter(env, "controller_node", "kf", -1.0)
        assert not ok and "kf" in reason and "range" in reason
        ok, reason = set_parameter(env, "controller_node", "mode", "PID")
        assert not ok and "mode must be one of OL, CL, DOB" in reason
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 500, 30)
        ok, reason = switch(env, "CL")
        switched_at["CL"] = time.monotonic()
        assert ok, reason
        wait_said("CL")
        n = col.count(EFFORT_COMMAND)
        assert col.wait_for(EFFORT_COMMAND, n + 1000, 30)
    finally:
        graph.stop()
        col.close()
    stamps, matches, values = laws(col, kf=1.0)
    assert stamps == sorted(stamps)
    # the controller names the last cycle of the old law; from the next cycle on every command is
    # the new law's ("the next cycle")
    last_old = {law: int(said[law].rsplit(" ", 1)[1]) for law in switched_at}
    assert last_old["DOB"] < last_old["CL"]

    def law_at(k: int) -> str:
        return "OL" if k <= last_old["DOB"] else "DOB" if k <= last_old["CL"] else "CL"

    # a command is judged when the collector holds the inputs of the law in force: on a loaded
    # machine this test's own subscriber can fall more than its 2000-sample history behind and
    # miss some (the controller had them: it waits for them)
    rows = list(zip(stamps, matches, values, strict=True))
    judged = [(k, m, v) for k, m, v in rows if law_at(k) in v[1]]
    assert len(judged) >= len(rows) // 2, (len(judged), len(rows))
    wrong = [(k, law_at(k), m, v) for k, m, v in judged if law_at(k) not in m]
    assert not wrong, f"{len(wrong)} commands not of the law in force: {wrong[:5]}"
    # the laws are told apart in most cycles (in contact, below the force limit), so the check
    # above has teeth
    only = [next(iter(m)) for _, m, v in rows if len(v[1]) == 3 and len(m) == 1]
    for law in ("OL", "DOB", "CL"):
        assert only.count(law) >= 100, (law, only.count(law))
