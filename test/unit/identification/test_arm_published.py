"""The whole-model identification on published arms (the UR5 and the Panda of
``example-robot-data``) whose hidden truth the test draws at random: link masses 10-20 % off
the URDF's, centres of mass 1-2 cm away, joint friction and armature the URDFs lack (the
Panda's states a placeholder damping of 0.003). Each arm gets an excitation designed from its
URDF, played 30 s on the truth by computed torque on the URDF; the identification knows only the
URDF and the record."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.core.models import UrdfModel
from haptic_dob.identification.arm_excitation_design import design_excitation
from haptic_dob.identification.arm_model import identify_arm_model
from haptic_sim.arm.device import ArmDeviceParams
from haptic_sim.arm.model_bench import ArmBench, free_motion, held_force, play
from haptic_sim.arm.truth import draw_truth
from support.published_arms import ARMS, ROBOTS, SKIP_REASON

#: the seed of each arm's truth (drawn by numpy's generator from it)
SEEDS = {"ur5": 11, "panda": 12}


@pytest.mark.slow
@pytest.mark.skipif(ROBOTS is None, reason=SKIP_REASON)
@pytest.mark.parametrize("arm", sorted(SEEDS))
def test_a_published_arm_with_a_hidden_truth_is_identified(arm: str) -> None:
    """Held-out residual under 3 % of the worst joint's torque span (CAD's reported), every
    link consistent, the observer on the identified model under 0.2 N in free motion and within
    3 % on a held 5 N, where CAD's is far off (measured: the table of
    docs/recording-and-analysis.md)."""
    assert ROBOTS is not None
    path, tip, start = ARMS[arm]
    cad_xml = (ROBOTS / path).read_text()
    cad = UrdfModel(cad_xml, tip)
    truth = UrdfModel(draw_truth(cad_xml, tip, SEEDS[arm]), tip)
    assert not np.allclose(truth.armature, cad.armature)
    design = design_excitation(cad, start, iterations=15)
    bench = ArmBench(
        truth,
        ArmDeviceParams(initial_position=start, encoder_resolution_rad=1e-6, velocity="exact"),
    )
    fit = identify_arm_model(
        cad_xml, tip, play(bench, cad, design.excitation, 30.0), turn_cutoff_hz=50.0
    )
    assert fit.residual_pct < 3.0 and fit.residual_cad_pct > 10.0, (
        fit.residual_pct,
        fit.residual_cad_pct,
    )
    for lf in fit.links:
        assert lf.mass > 0.0 and lf.pseudo_inertia_min > 0.0, lf
        assert all(lo <= c <= hi for lo, c, hi in zip(lf.box_lo, lf.com, lf.box_hi, strict=True))
    identified = UrdfModel(fit.urdf(cad_xml, "test"), tip)
    free = free_motion(bench, cad, identified)
    held = held_force(bench, cad, identified)
    assert np.max(free) < 0.2, np.max(free)
    assert np.linalg.norm(held - [0.0, 0.0, -5.0]) < 0.03 * 5.0, held
    held_cad = held_force(bench, cad, cad)
    assert np.linalg.norm(held_cad - [0.0, 0.0, -5.0]) > 0.1 * 5.0, held_cad
