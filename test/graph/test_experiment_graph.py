"""``haptic-experiment --quick`` through the node graph: it records OL, CL Kf=2 and DOB Kf=1 at
800 N/m; ``haptic-analyze`` on its bags gives the report's numbers, and a second run resumes from
the bags."""

from __future__ import annotations

import json
import signal
import subprocess
import time

import pytest

from haptic_sim.experiments.parts import CH7, load_results
from support.paths import tool


@pytest.mark.slow
@pytest.mark.multiprocess
def test_quick_experiment_runs_through_the_graph_resumes_and_haptic_analyze_reproduces_it(
    tmp_path,
) -> None:
    out = tmp_path / "report"
    argv = [tool("haptic-experiment"), "--quick", "--out", str(out)]
    # Ctrl-C once the first run is recorded: every launch stops, the complete bag stays
    proc = subprocess.Popen(
        argv,
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
        # a test run in the background inherits SIGINT ignored; Ctrl-C reaches a foreground tool
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    seen = []
    try:
        deadline = time.monotonic() + 180
        for line in proc.stdout:
            seen.append(line)
            if line.startswith("[  1/3]") or time.monotonic() > deadline:
                break
        assert seen and seen[-1].startswith("[  1/3]"), "".join(seen)  # progress as it runs
        proc.send_signal(signal.SIGINT)
        assert proc.wait(60) == 130, "".join(seen) + proc.stdout.read()
        seen += proc.stdout.readlines()
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait()
    left = subprocess.run(["pgrep", "-f", str(out)], capture_output=True, text=True)
    assert left.stdout.strip() == "", "launches still running after Ctrl-C"
    # the next run resumes from the recorded bag
    p = subprocess.run(argv, capture_output=True, text=True, timeout=240)
    assert p.returncode == 0, p.stdout + p.stderr
    # exactly the runs reported finished before the interrupt count as recorded (a run stopped
    # half-way is neither reported nor kept)
    finished = sum(line.startswith("[  ") for line in seen)
    assert f"{finished} of 3 runs already recorded (resuming)" in p.stdout, "".join(seen) + p.stdout
    ch7 = CH7.result_in(load_results(out / "results.json"))
    assert ch7 is not None
    assert {(r.mode, r.kf, r.wall) for r in ch7.rows} == {
        ("OL", 0.0, 800.0),
        ("CL", 2.0, 800.0),
        ("DOB", 1.0, 800.0),
    }
    report = (out / "report.md").read_text()
    assert "| OL |" in report and "Table 7.1" in report
    assert (out / "figures" / "ch7_transparency.png").stat().st_size > 10_000
    # every number comes from the bag: haptic-analyze on it prints the same figures
    for row in ch7.rows:
        assert row.segments == 1 and row.problem is None
        assert row.duration_s is not None and row.duration_s > 39.9  # the whole 40 s session
        a = subprocess.run(
            [tool("haptic-analyze"), row.bag, "--json"],
            capture_output=True,
            text=True,
            timeout=120,
        )
        assert a.returncode == 0, a.stderr
        (seg,) = json.loads(a.stdout)
        assert seg["controller"] == row.mode and seg["kf"] == row.kf
        assert seg["stiffness_n_per_m"] == row.wall
        assert seg["bandwidth_hz"] == row.bandwidth_hz
        assert seg["impedance_error_pct"] == row.impedance_error_pct
    # the thesis's ordering at 800 N/m: force feedback widens the band
    bw = {r.mode: r.bandwidth_hz for r in ch7.rows}
    assert bw["CL"] > bw["OL"] and bw["DOB"] > bw["OL"]
    # once everything is recorded, nothing runs again
    again = subprocess.run(argv, capture_output=True, text=True, timeout=120)
    assert again.returncode == 0, again.stderr
    assert "3 of 3 runs already recorded" in again.stdout
    assert "node-graph runs" in again.stdout and "simulated in" not in again.stdout
    assert CH7.result_in(load_results(out / "results.json")) == ch7
