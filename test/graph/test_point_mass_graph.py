"""A Cartesian device through the node graph in lockstep: excite, record, identify, DOB (issue 31).

The suite's device node simulates the point-mass device (``model: point_mass``, its truth in
``cartesian.*``); ``haptic-launch config/point_mass_excitation.yaml --record`` records the
excitation session as a real bag, ``haptic-identify --axes`` identifies every axis from that bag
and writes the model, and ``config/point_mass_sim.yaml`` with that model loaded after it renders
the floor under DOB, recorded again. Checked: each bag is the batch run of the same parameters to
the bit (``haptic_sim.device.batch``), the identification finds the hidden plant (mass within
5 %, viscous friction within 10 %), and the estimate recorded on the wire tracks the true hand
force recorded beside it within 5 % RMS of its span in contact.
"""

from __future__ import annotations

import json
import subprocess
from pathlib import Path
from typing import Any

import numpy as np
import pytest
import yaml

from haptic_dob.bag.bagfile import open_bag
from haptic_dob.bag.cdr import decode_vectors
from haptic_dob.bag.joints import read_joints
from haptic_dob.runtime.params import build, load_node_params, node_view
from haptic_msgs_py.topics import HAND_WRENCH, WRENCH_ESTIMATE
from haptic_sim.device.batch import load_session, run_batch
from haptic_sim.point_mass.device import PointMassDeviceParams
from support.paths import tool
from support.rosgraph import isolated_env, launch

pytestmark = [pytest.mark.multiprocess, pytest.mark.slow]

AXES = ("fd_x", "fd_y", "fd_z")
WRENCH = "geometry_msgs/msg/WrenchStamped"
SETTLE_S = 2.0  # the hand's ramp onto the floor


def record(config: Path, bag: Path, tmp_path: Path, name: str) -> None:
    """Run ``config`` through the graph in lockstep, recorded into ``bag``."""
    graph = launch(
        str(config), isolated_env(), log=tmp_path / f"{name}.log", extra=["--record", str(bag)]
    )
    try:
        assert graph.wait(600) == 0, graph.output()
    finally:
        graph.stop()


def vectors(bag: Path, topic: str) -> tuple[np.ndarray, np.ndarray]:
    """Stamps and (x, y, z) of a WrenchStamped topic, each stamp once, in order."""
    with open_bag(bag) as reader:
        conns = [c for c in reader.connections if c.topic == f"/{topic}"]
        datas = [data for _, _, data in reader.messages(connections=conns)]
    stamps, values = decode_vectors(datas, WRENCH, (0, 1, 2))
    stamps, first = np.unique(stamps, return_index=True)
    return stamps, values[first]


def session_with(config: Path, model_yaml: Path, out: Path) -> Path:
    """``config`` with the identified model's parameters laid over it, as one YAML."""
    doc: dict[str, Any] = yaml.safe_load(config.read_text())
    for section, body in yaml.safe_load(model_yaml.read_text()).items():
        doc.setdefault(section, {"ros__parameters": {}})["ros__parameters"].update(
            body["ros__parameters"]
        )
    out.write_text(yaml.safe_dump(doc, sort_keys=False))
    return out


def test_excite_record_identify_then_dob_through_the_graph(root: Path, tmp_path: Path) -> None:
    excitation = root / "config" / "point_mass_excitation.yaml"
    bag = tmp_path / "excitation"
    record(excitation, bag, tmp_path, "excitation")
    js = read_joints(bag, "joint_states", AXES)
    batch = run_batch(load_session(excitation))
    n = batch.q.shape[0]  # the graph also sends sample N, its last
    np.testing.assert_array_equal(js.stamps_ns[:n], batch.stamps_ns)
    np.testing.assert_array_equal(js.position[:n], batch.q)
    np.testing.assert_array_equal(js.effort[:n], batch.effort)

    model = tmp_path / "model.yaml"
    argv = [tool("haptic-identify"), str(bag), "--axes", ",".join(AXES), "--json"]
    cli = subprocess.run(
        [*argv, "--write-yaml", str(model)],
        capture_output=True,
        text=True,
        timeout=300,
    )
    assert cli.returncode == 0, cli.stderr
    fits = json.loads(cli.stdout)["axes"]
    truth = build(
        PointMassDeviceParams,
        node_view(load_node_params(excitation), "device_node"),
        "cartesian.",
    )
    for i, f in enumerate(fits):
        assert f["mass_kg"] == pytest.approx(truth.mass_kg[i], rel=0.05), f["joint"]
        assert f["viscous_n_s_per_m"] == pytest.approx(truth.viscous_n_s_per_m[i], rel=0.10)

    session = session_with(root / "config" / "point_mass_sim.yaml", model, tmp_path / "dob.yaml")
    dob_bag = tmp_path / "dob"
    record(session, dob_bag, tmp_path, "dob")
    nodes = load_session(session)
    assert nodes["/**"]["point_mass.mass_kg"] != nodes["observer_node"]["point_mass.mass_kg"]
    dob = run_batch(nodes)
    n = dob.q.shape[0]
    js = read_joints(dob_bag, "joint_states", AXES)
    np.testing.assert_array_equal(js.position[:n], dob.q)
    t_hand, hand = vectors(dob_bag, HAND_WRENCH)
    t_est, est = vectors(dob_bag, WRENCH_ESTIMATE)
    assert np.array_equal(t_hand[:n], dob.stamps_ns) and np.array_equal(t_est[:n], dob.stamps_ns)
    np.testing.assert_array_equal(est[:n], dob.force_estimated)
    np.testing.assert_array_equal(hand[:n], dob.hand_force)
    env = node_view(nodes, "environment_node")
    normal, point = np.asarray(env["normal"]), np.asarray(env["position"])
    contact = (js.position[:n] - point) @ normal > 0.0
    contact[: round(SETTLE_S * 1000)] = False
    err = np.linalg.norm(est[:n][contact] - hand[:n][contact], axis=1)
    rms, span = float(np.sqrt(np.mean(err**2))), float(np.ptp(hand[:n][contact] @ normal))
    assert contact.mean() > 0.85 and span > 1.5
    assert rms <= 0.05 * span, (rms, span)
