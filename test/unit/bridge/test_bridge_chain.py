"""The identification chain through the bridge's own code, in batch (issue 31).

Each device's chain as a lab runs it, every command on time (``support.bridge_batch``): the
excitation session (the bridge config with ``config/excite/<device>.yaml`` over it) -> the
loop's ``joint_states`` into a bag -> ``haptic-identify`` on that bag -> a DOB session with the
model it wrote, the hand pushing into the wall. Deterministic; it carries on where a loaded
machine makes the real-time test (``test/graph/realtime/test_bridge_chain.py``) skip.

- Force Dimension (``config/point_mass_sim.yaml``'s device): every axis's mass within 5 % and
  viscous friction within 10 % of the plant's truth, the estimate within 5 % RMS of the true
  hand force's span in contact.
- Touch (``config/phantom_omni_sim.yaml``'s): ``--inertial`` finds the 12 g payload (D(q) and
  G(q) within 5 %) and each joint's friction within 10 %; an OL session gives the Kalman
  velocity filter (``--velocity-noise``); the DOB on both estimates the hand within 5 %."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np
import pytest

from haptic_dob.cli.identify import main as identify
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models import UrdfModel
from haptic_dob.runtime.configs import urdf_beside
from haptic_dob.runtime.params import build, load_node_params, node_view
from support.bridge_batch import BridgeRecord, run_bridge
from support.drivers import plants
from support.drivers.run import SLIDE_HAND
from support.joint_bags import write_joint_states
from support.paths import ROOT

pytestmark = pytest.mark.slow

CONFIG = ROOT / "config"
EXCITE_S = 21.0  # the excitation overlays' duration_s
DOB_S = 8.0  # the hand's 1 s ramp, 2 s settling, then 6 s in contact
#: the Touch's hand: config/phantom_omni_sim.yaml's (a 1 N push onto the floor, a slow swing)
TOUCH_HAND = {
    k.removeprefix("hand."): v
    for k, v in load_node_params(plants.TOUCH_SIM)["device_node"].items()
    if k.startswith("hand.")
}
#: the Touch bridge's counts (rad): config/bridge_touch.yaml's state.encoder_resolution
TOUCH_COUNTS = ",".join(
    f"{c:g}"
    for c in load_node_params(CONFIG / "bridge_touch.yaml")["bridge_node"][
        "state.encoder_resolution"
    ]
)


def session(*files: Path, over: dict[str, dict[str, Any]] | None = None) -> dict[str, Any]:
    """The node sections of ``files`` laid over each other in order, then ``over``: what
    ``haptic-launch FILE --params FILE...`` gives the nodes."""
    out: dict[str, dict[str, Any]] = {}
    for f in files:
        nodes = load_node_params(f)
        urdf_beside(nodes, f)
        for node, values in nodes.items():
            out.setdefault(node, {}).update(values)
    for node, values in (over or {}).items():
        out.setdefault(node, {}).update(values)
    return out


def identified(record: BridgeRecord, tmp: Path, args: list[str]) -> Path:
    """``haptic-identify`` on the record's joint states as a bag: the model YAML it wrote."""
    bag = write_joint_states(
        tmp / "bag", record.stamps_ns, record.joint_names, record.q, record.effort, "mcap"
    )
    model = tmp / "model.yaml"
    assert identify([str(bag), *args, "--write-yaml", str(model)]) == 0
    return model


def contact_error(record: BridgeRecord, nodes: dict[str, Any]) -> tuple[float, float]:
    """The estimate's RMS error over the true force's span in contact, and the share of samples
    in contact after the settling."""
    share, rms, span = record.in_contact(build(VirtualWall, node_view(nodes, "environment_node")))
    return rms / span, share


@pytest.fixture(scope="module")
def fd(tmp_path_factory: pytest.TempPathFactory) -> tuple[dict[str, Any], dict[str, Any], float]:
    """The Force Dimension chain: the identified model, the plant's truth and the figure."""
    tmp = tmp_path_factory.mktemp("fd")
    config = CONFIG / "bridge_forcedimension.yaml"
    excite = session(config, CONFIG / "excite" / "forcedimension.yaml")
    plant = plants.point_mass(1000.0, 0, {"behaviour": "none"}, (0.0, 0.0, -1.0))
    record = run_bridge(excite, plant, EXCITE_S)
    model = identified(record, tmp, ["--axes", "fd_x,fd_y,fd_z"])
    dob = session(config, model, over={"controller_node": {"mode": "DOB"}})
    pusher = plants.point_mass(1000.0, 0, SLIDE_HAND, (1.0, 0.0, 0.0))
    error, share = contact_error(run_bridge(dob, pusher, DOB_S), dob)
    assert share > 0.9
    return load_node_params(model)["observer_node"], plant.truth()["cartesian"], error


def test_forcedimension_identification_finds_the_plant(fd) -> None:
    """Mass within 5 %, viscous friction within 10 % of the plant's truth on every axis
    (measured: +0.9-1.0 % and -0.8 to -1.4 %)."""
    model, truth, _ = fd
    for i in range(3):
        assert model["point_mass.mass_kg"][i] == pytest.approx(truth["mass_kg"][i], rel=0.05)
        got = model["point_mass.viscous_n_s_per_m"][i]
        assert got == pytest.approx(truth["viscous_n_s_per_m"][i], rel=0.10)


def test_forcedimension_dob_estimates_the_hand_within_5_percent(fd) -> None:
    """The estimate's RMS error in contact within 5 % of the true force's span (measured 4.5 %;
    4.6 % with the plant's truth as the model: the observer's lag, the encoder and stiction)."""
    assert fd[2] <= 0.05, fd[2]


def test_late_commands_are_reported_where_they_act_and_the_fit_holds(tmp_path: Path) -> None:
    """A quarter of the commands late (sent after the driver's next instant, the next state
    waiting in this process's queue) and a quarter sent after that instant but before its
    state could be heard (states heard 150 us after their stamps): the effort the bridge
    reports is, sample for sample, the one the plant had; the bridge counts them late; the fit
    is the one of every command on time. (When the bridge went by the order it heard states in,
    it reported 10230 of 21001 samples wrong with half the commands late, counted every command
    on time, and the viscous friction came out 6-10 % low. When it took a state's instant as
    the earliest the state could be heard, it reported the second quarter a cycle early: 15548
    of the 63003 values.)"""
    config = CONFIG / "bridge_forcedimension.yaml"
    excite = session(config, CONFIG / "excite" / "forcedimension.yaml")
    fits = []
    for late in (0.0, 0.25):
        plant = plants.point_mass(1000.0, 0, {"behaviour": "none"}, (0.0, 0.0, -1.0))
        record = run_bridge(excite, plant, EXCITE_S, late=late, state_delay_s=150e-6, crossing=late)
        np.testing.assert_array_equal(record.effort, record.applied)
        assert record.counts["on_time_pct"] == pytest.approx(100.0 * (1.0 - 2 * late), abs=2.0)
        assert record.counts["state_age_ms"] == pytest.approx(0.15)
        model = identified(record, tmp_path / f"late{late}", ["--axes", "fd_x,fd_y,fd_z"])
        fits.append(load_node_params(model)["observer_node"])
    for key in ("point_mass.mass_kg", "point_mass.viscous_n_s_per_m"):
        assert fits[1][key] == pytest.approx(fits[0][key], rel=0.01), key


def test_a_touchs_late_forces_are_reported_at_the_posture_they_act_in() -> None:
    """A Cartesian-force driver, a quarter of its forces late and a quarter sent after the next
    state's instant but before it could be heard (300 us after): the joint effort the bridge
    reports for [k-1, k) is, sample for sample, J(q_k-1)^T F of the force the driver held
    there (a late force acts a sample later, at a posture later than the state it answered)."""
    excite = session(CONFIG / "bridge_touch.yaml", CONFIG / "excite" / "touch.yaml")
    plant = plants.touch(500.0, 0, {"behaviour": "none"}, (0.0, 0.0, -1.0))
    record = run_bridge(excite, plant, 5.0, late=0.25, state_delay_s=300e-6, crossing=0.25)
    assert np.abs(record.applied).max() > 0.01  # it was pushing (N m)
    np.testing.assert_allclose(record.effort, record.applied, rtol=0.0, atol=1e-12)


def truth_model(truth: dict[str, Any]) -> dict[str, Any]:
    """The Touch plant's whole truth as the observer's model (its ``urdf.*`` parameters)."""
    return {
        "urdf.payload_kg": truth["payload_kg"],
        "urdf.viscous_n_m_s_per_rad": truth["viscous_n_m_s_per_rad"],
        "urdf.coulomb_n_m": truth["coulomb_n_m"],
        "urdf.coulomb_speed_rad_per_s": list(truth["coulomb_speed_rad_per_s"]),
    }


def touch_velocity(tmp: Path, seed: int) -> Path:
    """``haptic-identify --velocity-noise`` on the joint states of an OL session with the hand
    (seed ``seed``) pushing the stylus onto the floor, the bridge's config as it ships: the
    bridge's params file it wrote."""
    ol = session(CONFIG / "bridge_touch.yaml")
    record = run_bridge(ol, plants.touch(500.0, seed, TOUCH_HAND, (0.0, 0.0, -1.0)), DOB_S)
    bag = write_joint_states(
        tmp / f"ol{seed}", record.stamps_ns, record.joint_names, record.q, record.effort, "mcap"
    )
    out = tmp / f"velocity{seed}.yaml"
    args = [str(bag), "--velocity-noise", "--counts", TOUCH_COUNTS, "--write-yaml", str(out)]
    assert identify(args) == 0
    return out


def touch_dob(
    config: Path, model: dict[str, Any], velocity: Path | None, seed: int = 0
) -> tuple[float, float]:
    """The Touch's DOB session with ``model`` set on the nodes that assume one (as ``--set``
    does) and the bridge's ``velocity`` params file laid over the config (None: the config's
    adaptive window), the hand (seed ``seed``) pushing the stylus onto the floor: the
    estimate's RMS error in contact and the true force's span there (N)."""
    over = {n: {**model} for n in ("bridge_node", "observer_node", "controller_node")}
    over["controller_node"]["mode"] = "DOB"
    dob = session(config, *([velocity] if velocity else []), over=over)
    pusher = plants.touch(500.0, seed, TOUCH_HAND, (0.0, 0.0, -1.0))
    wall = build(VirtualWall, node_view(dob, "environment_node"))
    share, rms, span = run_bridge(dob, pusher, DOB_S).in_contact(wall)
    assert share > 0.9, share
    return rms, span


def test_touch_chain_finds_the_payload(tmp_path: Path) -> None:
    """The Touch through the bridge: ``haptic-identify --inertial --write-urdf`` on the
    excitation's bag finds the 12 g payload the URDF lacks. An arm's "mass" is its joint-space
    inertia D(q) and its weight G(q) over the session's postures: both within 5 % of the plant's
    (measured 0.15 % and 0.02 %, 0.07 %; the URDF's 18 % and 15 %, 21 %); each joint's viscous
    and Coulomb friction within 10 % (-0.2, +1.7, +6.8 % on the HD joints' counts; -0.3 to
    +0.1 %). ``--velocity-noise`` on an OL session (another draw of the hand) gives the
    bridge's Kalman velocity filter. The DOB estimate on that URDF and filter is within 5 % of
    the true force's span in contact (measured 4.7 %; 6.1 % with the config's adaptive window),
    and as good as on the plant's truth, within 5 % in newtons."""
    config = CONFIG / "bridge_touch.yaml"
    excite = session(config, CONFIG / "excite" / "touch.yaml")
    plant = plants.touch(500.0, 0, {"behaviour": "none"}, (0.0, 0.0, -1.0))
    truth = plant.truth()
    record = run_bridge(excite, plant, EXCITE_S)
    assert np.abs(record.effort).max(axis=0).tolist() < truth["effort_limits_n_m"]  # no saturation
    lo, hi = np.array(plant.model.position_limits).T  # the joints stay off their stops
    assert np.all(record.q.min(axis=0) > lo) and np.all(record.q.max(axis=0) < hi)
    bag = write_joint_states(
        tmp_path / "bag", record.stamps_ns, record.joint_names, record.q, record.effort, "mcap"
    )
    urdf = tmp_path / "touch.urdf"
    # the URDF by its installed name, as docs/devices.md types it
    args = ["--urdf", "urdf/phantom_omni.urdf", "--tip-frame", "tip", "--inertial"]
    assert identify([str(bag), *args, "--write-urdf", str(urdf)]) == 0
    found = UrdfModel(str(urdf), "tip")
    real = UrdfModel(CONFIG / "urdf" / "phantom_omni.urdf", "tip", payload_kg=truth["payload_kg"])
    postures = record.q[::50]
    D_found, D_real = (np.array([m.mass_matrix(q) for q in postures]) for m in (found, real))
    D_error = np.linalg.norm(D_found - D_real, axis=(1, 2)).mean()
    assert D_error <= 0.05 * np.linalg.norm(D_real, axis=(1, 2)).mean()
    rest = np.zeros(3)
    G_found, G_real = (
        np.array([m.inverse_dynamics(q, rest, rest) for q in postures]) for m in (found, real)
    )
    G_error = np.sqrt(np.mean((G_found - G_real) ** 2, axis=0))[1:]  # the waist lifts nothing
    assert np.all(G_error <= 0.05 * np.sqrt(np.mean(G_real**2, axis=0))[1:]), G_error
    np.testing.assert_allclose(found.coulomb, truth["coulomb_n_m"], rtol=0.10)
    # +14, +60, +57 % with the rigid body on the filtered motion, +2, +21, +20 % with friction
    # fitted at its turns too (docs/design/identification.md)
    np.testing.assert_allclose(found.viscous, truth["viscous_n_m_s_per_rad"], rtol=0.10)
    velocity = touch_velocity(tmp_path, seed=1)
    rms, span = touch_dob(config, {"urdf_path": str(urdf)}, velocity)
    best, _ = touch_dob(config, truth_model(truth), velocity)
    # in newtons: the two closed-loop sessions' spans may differ
    assert rms <= 1.05 * best, (rms, best)
    assert rms <= 0.05 * span, (rms, span)


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_the_kalman_velocity_filter_is_what_brings_the_touchs_estimate_within_5_percent(
    tmp_path: Path, seed: int
) -> None:
    """Three draws of the hand, the plant's truth as the model: with the config's adaptive
    window the estimate's RMS error in contact is above 5 % of the span (measured 6.1, 6.6,
    5.3 %); with the Kalman filter identified from an OL session of another draw it is within
    5 % (4.7, 4.7, 3.7 %), its RMS error in newtons at most 4/5 of the window's (0.72, 0.71,
    0.71 of it): the counts' velocity, not the model, is what the window lost."""
    truth = truth_model(plants.touch(500.0, 0, {"behaviour": "none"}, (0.0, 0.0, -1.0)).truth())
    config = CONFIG / "bridge_touch.yaml"
    velocity = touch_velocity(tmp_path, seed=(seed + 1) % 3)
    window, window_span = touch_dob(config, truth, None, seed)
    kalman, kalman_span = touch_dob(config, truth, velocity, seed)
    assert kalman <= 0.05 * kalman_span, (kalman, kalman_span)
    assert kalman <= 0.8 * window, (kalman, window)
    assert window > 0.05 * window_span, (window, window_span)
