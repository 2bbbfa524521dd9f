"""The teleoperation slave playing its excitation through the node graph, as the reproduction's
``slave`` part records it: the device node (the slave's hidden truth), the slave controller node
playing ``slave.trajectory_path`` (on joint_states alone: nothing publishes pose_desired), and a
recorder, in lockstep. The bag's joint states are the batch run's (``play_excitation``) to the
bit, so an identification of the one is an identification of the other."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest

from haptic_dob.bag.joints import read_joints
from haptic_dob.identification.arm_excitation import FourierExcitation
from haptic_dob.runtime.configs import config_dir
from haptic_sim.experiments.graph_runs import bag_path, execute
from haptic_sim.experiments.slave_model import slave_runs, teleop_config
from haptic_sim.teleop.slave_model import excitation_path, play_excitation
from support.rosgraph import random_domain

pytestmark = [pytest.mark.multiprocess]
SECONDS = 3.0


def test_the_graphs_bag_of_the_excitation_is_the_batch_runs(tmp_path) -> None:
    (run,) = slave_runs(config_dir() / "slide_sim.yaml", quick=True)
    device = {**run.params["device_node"], "duration_s": SECONDS}
    run = dataclasses.replace(run, params={**run.params, "device_node": device})
    execute(tmp_path, run, random_domain(), timeout_s=240.0)
    config = teleop_config()
    batch = play_excitation(config, FourierExcitation.load(excitation_path(config_dir())), SECONDS)
    graph = read_joints(bag_path(tmp_path, run), "joint_states", batch.names)
    assert len(graph.stamps_ns) == len(batch.stamps_ns) == round(SECONDS * 1000) + 1
    np.testing.assert_array_equal(graph.stamps_ns, batch.stamps_ns)
    np.testing.assert_array_equal(graph.position, batch.position)
    np.testing.assert_array_equal(graph.effort, batch.effort)
    assert np.max(np.abs(graph.position[-1] - graph.position[0])) > 0.05  # it played
