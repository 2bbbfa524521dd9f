"""Identification through the node graph (thesis ch. 4) and the observer against the sensor (5.3).

``haptic-experiment --parts ch4`` holds the simulated slide (stiction and an amplifier lag the
model leaves out) in the 80 N/m spring, adds the thesis's 2.4 N step, records the bag; least
squares on that bag's joint states must find the plant's truth, ``haptic-identify`` on the same
bag must agree, and the model it writes must load into an observer node as its assumed model.
"""

from __future__ import annotations

import json
import subprocess

import numpy as np
import pytest

from haptic_dob.bag.joints import read_joint
from haptic_dob.runtime.params import load_node_params
from haptic_sim.slide.plant import SlideDeviceParams
from haptic_sim.slide.session import SessionConfig, run_session
from support.paths import tool
from support.rosgraph import isolated_env

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]


def test_the_graph_bag_gives_the_plants_model_and_the_observer_loads_it(
    tmp_path, monkeypatch
) -> None:
    out = tmp_path / "report"
    run = subprocess.run(
        [tool("haptic-experiment"), "--parts", "ch4,ch5", "--out", str(out)],
        capture_output=True,
        text=True,
        timeout=600,
    )
    assert run.returncode == 0, run.stdout + run.stderr
    assert "PASS: least squares on the 2.4 N bag" in run.stdout, run.stdout
    results = json.loads((out / "results.json").read_text())["results"]["ch4"]
    ls = next(f for f in results["fits"] if f["method"] == "least_squares")
    truth = SlideDeviceParams()
    assert ls["mass_kg"] == pytest.approx(truth.mass_kg, rel=0.05)
    assert ls["viscous_n_s_per_m"] == pytest.approx(truth.viscous_n_s_per_m, rel=0.05)
    assert ls["coulomb_n"] == pytest.approx(truth.coulomb_n, rel=0.25)
    # the least-squares model predicts the verification runs to a fraction of a millimetre
    for p in results["predictions"]:
        if p["method"] == "least_squares":
            assert p["rms_error_mm"] < 0.5, p["excitation"]

    # thesis 5.3: the observer (the config's c = 7 N s/m, m/c = 60 ms) against the force sensor
    # and the true force, as recorded (lockstep: the same numbers on any machine; in batch
    # 0.746 / 0.749 N in free space and 0.356 / 0.357 N against the wall, nearly all the lag)
    free, wall = json.loads((out / "results.json").read_text())["results"]["ch5"]["runs"]
    assert free["rms_estimate_vs_sensor_n"] < 0.8 and free["rms_estimate_vs_true_n"] < 0.8
    assert wall["rms_estimate_vs_sensor_n"] < 0.4 and wall["rms_estimate_vs_true_n"] < 0.4
    assert free["clipped_pct"] == wall["clipped_pct"] == 0.0
    assert free["rms_sensor_vs_true_n"] < 0.02 and wall["rms_sensor_vs_true_n"] < 0.02

    # the lockstep graph with its excitation is the batch run, to the bit
    run_dir = out / "runs" / "ch4_step_2p4"
    cfg = SessionConfig.from_node_params(load_node_params(run_dir / "params.yaml"))
    batch = run_session(cfg).q  # samples 0..N-1; the graph also sends sample N, its last
    np.testing.assert_array_equal(read_joint(run_dir / "bag").position[: len(batch)], batch)

    bag, model = run_dir / "bag", tmp_path / "model.yaml"
    cli = subprocess.run(
        [tool("haptic-identify"), str(bag), "--json", "--write-yaml", str(model)],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert cli.returncode == 0, cli.stderr
    fit = json.loads(cli.stdout)
    assert fit["mass_kg"] == pytest.approx(ls["mass_kg"], rel=1e-9)

    import rclpy
    from rclpy.context import Context

    from haptic_dob.nodes.observer_node import ObserverNode

    monkeypatch.setenv("ROS_DOMAIN_ID", isolated_env()["ROS_DOMAIN_ID"])
    ctx = Context()
    rclpy.init(context=ctx, args=["--ros-args", "--params-file", str(model)])
    try:
        node = ObserverNode(context=ctx)
        try:
            assert node.model.mass_kg == pytest.approx(fit["mass_kg"])
            assert node.model.coulomb_n == pytest.approx(fit["coulomb_n"])
        finally:
            node.destroy_node()
    finally:
        rclpy.try_shutdown(context=ctx)
