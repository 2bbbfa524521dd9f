"""``make demo`` / ``haptic-demo``: the default simulated virtual-wall session and its result."""

from __future__ import annotations

import sys

from haptic_dob.analysis.transparency import mass_damper_band_edge_hz
from haptic_dob.cli.common import ArgumentParser, run
from haptic_dob.runtime.configs import resolve_config
from haptic_sim.slide.session import SessionConfig, run_session
from haptic_sim.slide.stability import law_for

#: the thesis's Table 7.1 / 7.2 entries at 800 N/m (bandwidth Hz, impedance error %)
THESIS_800 = {"OL": (3.8, 30.5), "CL": (5.5, 30.4), "DOB": (5.1, 34.0)}


def command(config: str) -> int:
    """Run OL, CL (Kf 2) and DOB (Kf 1) on the config's wall and print a small table."""
    cfg = SessionConfig.from_yaml(resolve_config(config))
    m = cfg.model
    k = cfg.wall.stiffness_n_per_m
    print(
        f"haptic_dob demo: {cfg.loop.duration_s:g} s simulated sessions at "
        f"{cfg.loop.rate_hz:g} Hz, "
        f"1-DOF slide (m {m.mass_kg} kg, b {m.viscous_n_s_per_m} N s/m, Fc {m.coulomb_n} N), "
        f"semi-random hand, {k:g} N/m wall, observer c = {cfg.observer.gain:g} N s/m"
    )
    print(
        f"{'controller':<12}{'bandwidth':>11}{'imp. error':>12}{'est. error':>12}"
        f"{'saturated':>11}   thesis at 800 N/m"
    )
    for name, kf in (("OL", 0.0), ("CL", 2.0), ("DOB", 1.0)):
        res = run_session(cfg.replace(law=law_for(name, kf, cfg.law.max_force_n)))
        s = res.summary()
        label = name if name == "OL" else f"{name} Kf={kf:g}"
        bw, err = THESIS_800[name]
        print(
            f"{label:<12}{s.bandwidth_hz:>8.2f} Hz{s.impedance_error_pct:>10.1f} %"
            f"{s.estimate_rms_error_n:>10.3f} N{s.saturated_pct:>9.1f} %   {bw} Hz, {err} %"
        )
    print(
        f"OL mass-damper prediction: {mass_damper_band_edge_hz(k, m.mass_kg):.2f} Hz. "
        "Bandwidth: first exit of |Z_hat/Z_d| from +-3 dB (H1, Welch, Hann, 2 s segments); "
        "est. error: RMS of the observer's hand-force estimate."
    )
    return 0


def main(argv: list[str] | None = None) -> int:
    """Entry point of ``haptic-demo``."""
    p = ArgumentParser(prog="haptic-demo", description=__doc__)
    p.add_argument("--config", default="slide_sim", help="session YAML (default: slide_sim)")
    a = p.parse_args(argv)
    return run(lambda: command(a.config))


if __name__ == "__main__":
    sys.exit(main())
