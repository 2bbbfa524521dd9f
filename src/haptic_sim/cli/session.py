"""``haptic-session``: run one simulated session in batch and print its headline figures."""

from __future__ import annotations

import dataclasses
import json
import sys
from dataclasses import dataclass
from pathlib import Path

from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.core.control import ControlMode
from haptic_dob.core.environment import VirtualWall
from haptic_dob.core.validation import nonnegative, positive
from haptic_dob.runtime.configs import resolve_config
from haptic_dob.runtime.params import load_node_params, node_view
from haptic_sim.arm.session import ArmSessionConfig, ArmSessionSummary, run_arm_session
from haptic_sim.device.batch import BatchSummary, load_session, run_batch, summarize
from haptic_sim.slide.session import SessionConfig, SessionSummary, run_session
from haptic_sim.slide.stability import law_for


def command(
    config: str,
    controller: str | None,
    kf: float | None,
    stiffness: float | None,
    duration: float | None,
    seed: int | None,
    save: str | None,
    as_json: bool,
) -> int:
    """Load, override, run, print; raises ``ValueError``/``InputError`` on bad input."""
    path = resolve_config(config)
    model = node_view(load_node_params(path), "device_node").get("model", "slide")
    if model == "point_mass":
        overrides = Overrides(controller, kf, stiffness, duration, seed)
        print_summary(run_cartesian(path, overrides, save), save, as_json)
        return 0
    if model != "slide":
        print_summary(run_arm(path, controller, kf, stiffness, duration, seed, save), save, as_json)
        return 0
    cfg = SessionConfig.from_yaml(path)
    if controller is not None or kf is not None:
        law = cfg.law
        cfg = cfg.replace(
            law=law_for(controller or law.mode.value, law.kf if kf is None else kf, law.max_force_n)
        )
    if stiffness is not None:
        k = positive("--stiffness", stiffness)
        w = cfg.wall
        cfg = cfg.replace(wall=VirtualWall(k, w.damping_n_s_per_m, w.position, w.normal))
    if duration is not None:
        cfg = cfg.replace(loop__duration_s=positive("--duration", duration))
    if seed is not None:
        cfg = cfg.replace(loop__seed=int(nonnegative("--seed", seed)))
    result = run_session(cfg)
    if save:
        result.save(save)
    print_summary(result.summary(), save, as_json)
    return 0


def run_arm(
    path: Path,
    controller: str | None,
    kf: float | None,
    stiffness: float | None,
    duration: float | None,
    seed: int | None,
    save: str | None,
) -> ArmSessionSummary:
    """A PHANToM or URDF-arm session (``haptic_sim.arm.session``) with the same overrides."""
    cfg = ArmSessionConfig.from_yaml(path)
    if controller is not None or kf is not None:
        law = cfg.law
        cfg = cfg.replace(
            law=law_for(controller or law.mode.value, law.kf if kf is None else kf, law.max_force_n)
        )
    if stiffness is not None:
        w = cfg.wall
        cfg = cfg.replace(
            wall=VirtualWall(
                positive("--stiffness", stiffness), w.damping_n_s_per_m, w.position, w.normal
            )
        )
    if duration is not None:
        cfg = cfg.replace(loop__duration_s=positive("--duration", duration))
    if seed is not None:
        cfg = cfg.replace(loop__seed=int(nonnegative("--seed", seed)))
    result = run_arm_session(cfg)
    if save:
        result.save(save)
    return result.summary()


@dataclass(frozen=True)
class Overrides:
    """What the command line changes in a config (None: the config's)."""

    controller: str | None
    kf: float | None
    stiffness: float | None
    duration: float | None
    seed: int | None


def run_cartesian(path: Path, o: Overrides, save: str | None) -> BatchSummary:
    """A Cartesian point-mass device's session (``haptic_sim.device.batch``), the overrides set
    as the nodes' parameters (``--stiffness`` leaves the hand's push as the config has it):
    headline figures of the estimate in contact."""
    nodes = load_session(path)
    ctl, env, dev = (
        nodes.setdefault(n, {}) for n in ("controller_node", "environment_node", "device_node")
    )
    if o.controller is not None:
        ctl["mode"] = o.controller
    if o.kf is not None:
        ctl["kf"] = nonnegative("--kf", o.kf)
    if o.stiffness is not None:
        env["stiffness_n_per_m"] = positive("--stiffness", o.stiffness)
    if o.duration is not None:
        dev["duration_s"] = positive("--duration", o.duration)
    if o.seed is not None:
        dev["seed"] = int(nonnegative("--seed", o.seed))
    record = run_batch(nodes)
    if save:
        record.save(save)
    return summarize(record, nodes)


def print_summary(
    figures: SessionSummary | ArmSessionSummary | BatchSummary, saved: str | None, as_json: bool
) -> None:
    """JSON, or one aligned ``key  value`` line per figure (and where the arrays went)."""
    summary: dict[str, object] = dict(dataclasses.asdict(figures))
    if saved:
        summary["saved"] = saved
    if as_json:
        print(json.dumps(summary, indent=2))
        return
    width = max(len(k) for k in summary)
    for key, value in summary.items():
        text = f"{value:.4g}" if isinstance(value, float) else str(value)
        if value is None:
            text = "n/a (record too short or no motion)"
        print(f"{key:<{width}}  {text}")


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-session``."""
    p = ArgumentParser(
        prog="haptic-session",
        description="Run one simulated haptic session in batch (the node graph's exact timing) "
        "and print transparency, force-estimate error, contact, saturation and energy.",
    )
    p.add_argument("--config", default="slide_sim", help="session YAML (default: slide_sim)")
    p.add_argument(
        "--controller",
        type=str.upper,
        choices=[m.value for m in ControlMode],
        help="override the control law",
    )
    p.add_argument("--kf", type=float, help="override the force-feedback gain Kf")
    p.add_argument(
        "--stiffness",
        type=float,
        metavar="N_PER_M",
        help="override the wall stiffness (the hand pushes to the same depth)",
    )
    p.add_argument("--duration", type=float, metavar="S", help="override the length in seconds")
    p.add_argument("--seed", type=int, help="override the seed")
    p.add_argument("--save", metavar="NPZ", help="write the per-cycle arrays to this .npz file")
    p.add_argument("--json", action="store_true", help="print JSON")
    a = p.parse_args(argv)
    return run(
        lambda: command(
            a.config, a.controller, a.kf, a.stiffness, a.duration, a.seed, a.save, a.json
        )
    )


if __name__ == "__main__":
    sys.exit(main())
