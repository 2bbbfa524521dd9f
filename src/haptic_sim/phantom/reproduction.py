"""Thesis section 5.2 on the simulated PHANToM 1.5: batch reproductions and their figures.

- 5.2.1, free motion under gravity: no actuation, the observer's model without G
  (``PhantomModel(gravity=False)``), gain c = 2. Reported: RMS and peak of ``d_hat - (-G)`` per
  joint (N m), after the first 0.1 s.
- 5.2.2, a 1000 N/m undamped wall 0.01 m below the start, gravity pulling the device into it, no
  hand, DOB with Kf = 1 and Kf = 50, the observer's model again without G; once with the
  observer's wrench, once with the exact one (``ArmSessionConfig.exact_force``); held at rest for
  ``hold_s``, then released (t = 0). Reported per Kf: the largest distance between the two tip
  trajectories over the comparison window, the same for two exact runs 1e-6 rad apart on phi2,
  and the peak-to-peak height of the tip after first contact.

Both: appendix-B parameters, ideal encoder, exact joint velocity (``velocity='difference'``:
a driver's backward difference); figures as PNG (matplotlib's Agg). docs/design/arms.md.
"""

from __future__ import annotations

import argparse
import json
import sys
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.core.control import ControlMode, ImpedanceLaw
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.models.phantom import HOME, PhantomModel
from haptic_dob.core.observers.factory import ObserverSettings
from haptic_dob.core.tip_force import dls_transpose_solve
from haptic_sim.arm.device import ArmDeviceParams
from haptic_sim.arm.session import ArmSessionConfig, ArmSessionResult, run_arm_session
from haptic_sim.slide.session import LoopSettings

#: 5.2.1 start: upper arm 0.3 rad up, crank at 1 rad (the arm swings through a large range)
FREE_MOTION_START = (0.0, 0.3, 1.0)
GAIN = 2.0
WALL_STIFFNESS_N_PER_M = 1000.0
WALL_GAP_M = 0.01
KF_VALUES = (1.0, 50.0)


@dataclass(frozen=True)
class Setup:
    """Common settings of the reproductions."""

    params: str = "appendix_b"
    gain: float = GAIN
    velocity: str = "exact"
    encoder_resolution_rad: float = 0.0

    def device(self, start: tuple[float, ...]) -> ArmDeviceParams:
        """The simulated PHANToM: ideal encoder, no hand, start pose ``start``."""
        return ArmDeviceParams(
            encoder_resolution_rad=self.encoder_resolution_rad,
            initial_position=list(start),
            velocity=self.velocity,
        )


def free_motion(setup: Setup = Setup(), duration_s: float = 3.0) -> ArmSessionResult:
    """Thesis 5.2.1: the arm falls and swings freely; the observer estimates -G."""
    cfg = ArmSessionConfig(
        loop=LoopSettings(duration_s=duration_s),
        plant=PhantomModel(setup.params),
        observer_model=PhantomModel(setup.params, gravity=False),
        device=setup.device(FREE_MOTION_START),
        law=ImpedanceLaw(ControlMode.OL, 0.0, 8.5),
        observer=ObserverSettings(setup.gain, 0.0),
    )
    return run_arm_session(cfg)


def free_motion_errors(result: ArmSessionResult, skip_s: float = 0.1) -> dict[str, list[float]]:
    """RMS and peak of ``d_hat + G`` per joint (N m), leaving out the first ``skip_s``."""
    s = slice(round(skip_s / (result.t[1] - result.t[0])), None)
    err = result.d_hat[s] - result.d_exact[s]
    return {
        "rms_error_n_m": np.sqrt(np.mean(err * err, axis=0)).tolist(),
        "max_error_n_m": np.max(np.abs(err), axis=0).tolist(),
        "gravity_range_n_m": np.ptp(result.d_exact[s], axis=0).tolist(),
    }


def wall_setup(params: str = "appendix_b") -> tuple[VirtualWall, np.ndarray]:
    """The 5.2.2 wall: 1000 N/m, its plane 0.01 m below the start, normal pointing down."""
    p0 = PhantomModel(params).forward_kinematics(HOME)
    plane = p0 - np.array([0.0, 0.0, WALL_GAP_M])
    wall = VirtualWall(WALL_STIFFNESS_N_PER_M, 0.0, tuple(plane.tolist()), (0.0, 0.0, -1.0))
    return wall, p0


def wall_contact(
    kf: float,
    exact: bool,
    setup: Setup = Setup(),
    duration_s: float = 1.0,
    hold_s: float = 0.1,
    start: tuple[float, ...] = HOME,
) -> ArmSessionResult:
    """Thesis 5.2.2: released above the wall, DOB control with gain ``kf``."""
    wall, _ = wall_setup(setup.params)
    cfg = ArmSessionConfig(
        loop=LoopSettings(duration_s=duration_s),
        plant=PhantomModel(setup.params),
        observer_model=PhantomModel(setup.params, gravity=False),
        device=setup.device(start),
        wall=wall,
        law=ImpedanceLaw(ControlMode.DOB, kf, 8.5),
        observer=ObserverSettings(setup.gain, 0.0),
        exact_force=exact,
        hold_s=hold_s,
    )
    return run_arm_session(cfg)


def _exact_wrench(r: ArmSessionResult) -> np.ndarray:
    """The exact disturbance of each sample as a tip force (N), as the exact mode computes it."""
    model = r.config.observer_model or r.config.plant
    obs = r.config.observer.build(model, r.t[1] - r.t[0])
    return np.array(
        [
            dls_transpose_solve(model.jacobian(q), d, obs.dls_threshold_m, obs.dls_damping_m)
            for q, d in zip(r.q_true, r.d_exact, strict=True)
        ]
    )


def _separation(a: ArmSessionResult, b: ArmSessionResult, n: int) -> float:
    """Largest distance (m) between two end-effector trajectories over the first n cycles."""
    return float(np.max(np.linalg.norm(a.ee_true[:n] - b.ee_true[:n], axis=1)))


def wall_metrics(
    runs: dict[str, ArmSessionResult], wall: VirtualWall, window_s: float
) -> dict[str, Any]:
    """Separation of DOB vs exact (and of two nearby exact runs) and the oscillation."""
    dob, exact, nearby = runs["dob"], runs["exact"], runs["nearby"]
    dt = dob.t[1] - dob.t[0]
    n = round(window_s / dt)
    out: dict[str, Any] = {"window_s": window_s}
    out["dob_vs_exact_max_m"] = _separation(dob, exact, n)
    out["dob_vs_exact_height_max_m"] = float(
        np.max(np.abs(dob.ee_true[:n, 2] - exact.ee_true[:n, 2]))
    )
    out["nearby_exact_max_m"] = _separation(exact, nearby, n)
    # the observer's tip-force error in the DOB run (vs the exact force at the same state)
    err = dob.force_estimated[:n] - _exact_wrench(dob)[:n]
    out["dob_force_error_rms_n"] = float(np.sqrt(np.mean(np.sum(err * err, axis=1))))
    # separation over time: first time each pair is 1 mm apart (None: never in the run)
    for key, (a, b) in {"dob_vs_exact": (dob, exact), "nearby_exact": (exact, nearby)}.items():
        d = np.linalg.norm(a.ee_true - b.ee_true, axis=1)
        over = np.nonzero(d > 1e-3)[0]
        out[f"{key}_1mm_at_s"] = float(dob.t[over[0]]) if over.size else None
    for name, r in (("dob", dob), ("exact", exact)):
        z = r.ee_true[:n, 2]
        inside = np.nonzero(z < wall.position[2])[0]
        first = int(inside[0]) if inside.size else n
        out[f"{name}_first_contact_s"] = float(r.t[first]) if inside.size else None
        out[f"{name}_height_ptp_m"] = float(np.ptp(z[first:])) if inside.size else 0.0
        out[f"{name}_max_penetration_m"] = float(max(0.0, wall.position[2] - z.min()))
    return out


# --- figures ----------------------------------------------------------------------------------
def _figure(width: float = 8.0, height: float = 5.0) -> Any:
    from matplotlib.figure import Figure  # lazy: the sessions alone run without matplotlib

    return Figure(figsize=(width, height), dpi=100)


def plot_free_motion(result: ArmSessionResult, path: Path, errors: dict[str, Any]) -> None:
    """Estimate vs -G on joints 2 and 3 (the thesis's Figure 5.1)."""
    fig = _figure(8.0, 6.0)
    axes = fig.subplots(2, 1, sharex=True)
    for ax, j in zip(axes, (1, 2), strict=True):
        ax.plot(result.t, result.d_exact[:, j], "k-", lw=1.5, label="-G (true)")
        ax.plot(result.t, result.d_hat[:, j], "r:", lw=1.5, label="observer estimate")
        rms = errors["rms_error_n_m"][j]
        ax.set_ylabel(f"joint {j + 1} (N m)")
        ax.set_title(f"joint {j + 1}: RMS error {rms * 1e3:.1f} mN m", fontsize=10)
        ax.grid(True, alpha=0.3)
    axes[0].legend(loc="upper right", fontsize=9)
    axes[-1].set_xlabel("time (s)")
    fig.suptitle("Thesis 5.2.1: free motion under gravity, G left out of the observer, c = 2")
    fig.tight_layout()
    fig.savefig(path)


def plot_wall(
    runs: dict[float, dict[str, ArmSessionResult]],
    wall: VirtualWall,
    path: Path,
    window_s: float | None = None,
) -> None:
    """End-effector height, DOB (solid) vs exact force (dashed), Kf = 1 and 50 (Figure 5.2)."""
    fig = _figure(8.0, 6.0)
    axes = fig.subplots(len(runs), 1, sharex=True)
    for ax, (kf, r) in zip(np.atleast_1d(axes), runs.items(), strict=True):
        t = r["dob"].t
        ax.axhline(wall.position[2] * 1e3, color="0.6", lw=1, label="wall")
        if window_s is not None:
            ax.axvspan(0.0, window_s, color="0.9", zorder=0, label="comparison window")
        ax.plot(t, r["dob"].ee_true[:, 2] * 1e3, "b-", lw=1.2, label="DOB estimate")
        ax.plot(t, r["exact"].ee_true[:, 2] * 1e3, "r--", lw=1.2, label="exact force")
        ax.set_ylabel("height z (mm)")
        ax.set_title(f"Kf = {kf:g}", fontsize=10)
        ax.grid(True, alpha=0.3)
    np.atleast_1d(axes)[0].legend(loc="upper right", fontsize=9)
    np.atleast_1d(axes)[-1].set_xlabel("time since release (s)")
    fig.suptitle("Thesis 5.2.2: 1000 N/m wall 0.01 m below the start, gravity, no hand")
    fig.tight_layout()
    fig.savefig(path)


# --- the whole reproduction -------------------------------------------------------------------
def reproduce_free_motion(
    out_dir: Path | None, setup: Setup = Setup(), duration_s: float = 3.0
) -> dict[str, Any]:
    """Run 5.2.1; write ``thesis_5_2_1.png`` to ``out_dir`` (if given); return the numbers."""
    result = free_motion(setup, duration_s)
    errors = free_motion_errors(result)
    out: dict[str, Any] = {"start": list(FREE_MOTION_START), "duration_s": duration_s, **errors}
    if out_dir is not None:
        path = Path(out_dir) / "thesis_5_2_1.png"
        plot_free_motion(result, path, errors)
        out["figure"] = str(path)
    return out


def reproduce_wall(
    out_dir: Path | None,
    setup: Setup = Setup(),
    duration_s: float = 1.0,
    window_s: float = 0.3,
    kfs: tuple[float, ...] = KF_VALUES,
) -> dict[str, Any]:
    """Run 5.2.2 for each Kf; write ``thesis_5_2_2.png``; return the numbers per Kf."""
    wall, p0 = wall_setup(setup.params)
    nearby_start = (HOME[0], HOME[1] + 1e-6, HOME[2])
    runs: dict[float, dict[str, ArmSessionResult]] = {}
    out: dict[str, Any] = {"start_m": p0.tolist(), "wall_z_m": wall.position[2]}
    for kf in kfs:
        runs[kf] = {
            "dob": wall_contact(kf, False, setup, duration_s),
            "exact": wall_contact(kf, True, setup, duration_s),
            "nearby": wall_contact(kf, True, setup, duration_s, start=nearby_start),
        }
        out[f"kf_{kf:g}"] = wall_metrics(runs[kf], wall, window_s)
    if out_dir is not None:
        path = Path(out_dir) / "thesis_5_2_2.png"
        plot_wall(runs, wall, path, window_s)
        out["figure"] = str(path)
    return out


def command(out_dir: str, as_json: bool = False) -> int:
    """Run both reproductions, write the figures to ``out_dir`` and print the numbers."""
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    results = {"5.2.1": reproduce_free_motion(out), "5.2.2": reproduce_wall(out)}
    if as_json:
        print(json.dumps(results, indent=2))
        return 0
    r1 = results["5.2.1"]
    rms, peak = r1["rms_error_n_m"], r1["max_error_n_m"]
    print("5.2.1 free motion, G left out of the observer, c = 2 (N m):")
    for j in (1, 2):
        print(f"  joint {j + 1}: RMS error {rms[j]:.4f}, peak {peak[j]:.4f}")
    print(f"  figure: {r1['figure']}")
    r2 = results["5.2.2"]
    print("5.2.2 wall 1000 N/m, 0.01 m below the start, DOB vs exact force:")
    for key, m in r2.items():
        if not key.startswith("kf_"):
            continue
        print(
            f"  Kf = {key[3:]}, first {m['window_s']:g} s: height apart "
            f"{m['dob_vs_exact_height_max_m'] * 1e3:.3f} mm, "
            f"3-D {m['dob_vs_exact_max_m'] * 1e3:.3f} mm "
            f"(two exact runs 1e-6 rad apart: {m['nearby_exact_max_m'] * 1e3:.4f} mm); DOB force "
            f"error {m['dob_force_error_rms_n'] * 1e3:.1f} mN RMS; height peak-to-peak after "
            f"contact {m['dob_height_ptp_m'] * 1e3:.1f} mm (DOB), "
            f"{m['exact_height_ptp_m'] * 1e3:.1f} mm (exact)"
        )
    print(f"  figure: {r2['figure']}")
    return 0


def main(argv: list[str] | None = None) -> int:
    """``haptic-phantom-figures [--out DIR] [--json]``."""
    p = argparse.ArgumentParser(description="Reproduce thesis section 5.2 on the PHANToM 1.5.")
    p.add_argument("--out", default="figures", help="directory for the PNG figures")
    p.add_argument("--json", action="store_true", help="print the numbers as JSON")
    a = p.parse_args(argv)
    try:
        return command(a.out, a.json)
    except (OSError, ValueError) as exc:
        print(f"ERROR: {exc}", file=sys.stderr)
        return 2


if __name__ == "__main__":
    sys.exit(main())
