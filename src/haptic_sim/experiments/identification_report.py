"""Chapter 4's section of the report: tables, figures and terminal lines from ``Ch4Result``."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.identification.filters import plus_minus
from haptic_dob.identification.one_dof import SlideFit
from haptic_sim.experiments.figures import pyplot, save_figure
from haptic_sim.experiments.identification import IDENTIFY, TRACE_HZ, VERIFY, Ch4Result, run_name
from haptic_sim.experiments.tables import fmt
from haptic_sim.slide.session import SessionConfig

#: the thesis's identified slide (Table 4.1)
THESIS_TABLE_4_1 = (0.416, 1.272, 0.24)
METHOD_NAMES = {
    "least_squares": "least squares",
    "step": "step method, the swings' decay",
    "thesis_step": "step method, the thesis's formulas (4.2)",
}


def _row(fit: SlideFit) -> str:
    m = plus_minus(fit.mass_kg, fit.mass_std, ".4f", "–")
    c = plus_minus(fit.viscous_n_s_per_m, fit.viscous_std, ".3f", "–")
    fc = plus_minus(fit.coulomb_n, fit.coulomb_std, ".3f", "–")
    return f"| identified: {METHOD_NAMES[fit.method]} | {m} | {c} | {fc} |"


def ch4_tables(r: Ch4Result, base: SessionConfig) -> str:
    """The identified models beside the plant's truth and the thesis; the verification errors."""
    d = base.device
    m, c, fc = THESIS_TABLE_4_1
    lines = [
        "**The models** (identified from the 2.4 N step's bag, its joint states alone):",
        "",
        "| model | m (kg) | c (N s/m) | Fc (N) |",
        "|---|---|---|---|",
        f"| the simulated plant's truth (`plant.*`; with stiction {d.stiction_ratio:g} x Fc over "
        f"{1e3 * d.stribeck_velocity_m_per_s:g} mm/s and a {1e3 * d.amplifier_lag_s:g} ms "
        f"amplifier lag) | {d.mass_kg:.4f} | {d.viscous_n_s_per_m:.3f} | {d.coulomb_n:.3f} |",
        *(_row(f) for f in r.fits),
        f"| thesis Table 4.1 (its device, the step method and a separate Fc) | {m} | {c} | {fc} |",
        "",
        "**Model verification** (each model alone, under the same spring and input, against the "
        "recorded positions; RMS error / final position error, mm):",
        "",
        "| input | " + " | ".join(METHOD_NAMES[f.method] for f in r.fits) + " |",
        "|---|" + "---|" * len(r.fits),
    ]
    for e in (IDENTIFY, *VERIFY):
        name = run_name(e)
        cols = [
            f"{p.rms_error_mm:.2f} / {p.final_error_mm:+.2f}"
            for f in r.fits
            for p in r.predictions
            if p.run == name and p.method == f.method
        ]
        if cols:
            lines.append(f"| {e.label()} | " + " | ".join(cols) + " |")
    return "\n".join(lines) + "\n"


def ch4_notes(_r: Ch4Result) -> str:
    """What the section shows and how the step method tells friction from damping."""
    return (
        "The step method reads the damping from the decay of the swings. Coulomb friction takes "
        "a constant amount out of every swing (it moves each half swing's equilibrium by Fc/k "
        "against the motion) where viscous damping takes a fixed ratio, so the swings' "
        "amplitudes give both; from the first overshoot alone, as in the thesis, friction reads "
        "as damping and c comes out about 1.6 times too high. Least squares fits m, c and Fc "
        "together on the samples that move (with a Stribeck term it leaves out of the model), "
        "so stiction and the amplifier lag, which the model leaves out, are what remains in its "
        "predictions.\n"
    )


def _t(n: int) -> np.ndarray:
    return np.arange(n) / TRACE_HZ


def plot_identification(r: Ch4Result, path: Path, _base: SessionConfig) -> None:
    """Thesis figure 4.2: the 2.4 N step, measured and predicted by each model."""
    plt = pyplot()
    fig, ax = plt.subplots(figsize=(6.4, 4.8))
    _plot_run(ax, r, run_name(IDENTIFY))
    ax.set_title(f"Identification: {IDENTIFY.label()} under the 80 N/m spring")
    save_figure(fig, path)


def plot_verification(r: Ch4Result, path: Path, _base: SessionConfig) -> None:
    """Thesis figure 4.3: the 1.6 N and 3.2 N steps and the 0.6 N, 2 Hz sine."""
    plt = pyplot()
    fig, axes = plt.subplots(1, len(VERIFY), figsize=(12, 4.6))
    for ax, e in zip(axes, VERIFY, strict=True):
        _plot_run(ax, r, run_name(e))
        ax.set_title(f"Verification: {e.label()}")
    save_figure(fig, path)


def _plot_run(ax: Any, r: Ch4Result, name: str) -> None:
    x = r.measured_mm[name]
    ax.plot(_t(len(x)), x, "k", lw=1.2, label="measured (the graph's bag)")
    for i, p in enumerate(p for p in r.predictions if p.run == name):
        ax.plot(
            _t(len(p.predicted_mm)),
            p.predicted_mm,
            color=f"C{i}",
            ls="--",
            lw=1.0,
            label=f"{METHOD_NAMES[p.method]} (RMS {p.rms_error_mm:.2f} mm)",
        )
    ax.set_xlabel("time (s)")
    ax.set_ylabel("position (mm)")
    ax.grid(True, alpha=0.3)
    ax.legend(fontsize=7, loc="upper center", bbox_to_anchor=(0.5, -0.18))  # under the traces


def ch4_console(r: Ch4Result) -> list[str]:
    """The identified models, one line each."""
    return [
        f"identified ({METHOD_NAMES[f.method]}): m {f.mass_kg:.4f} kg, c "
        f"{f.viscous_n_s_per_m:.3f} N s/m, Fc {fmt(f.coulomb_n, '.3f')} N"
        for f in r.fits
    ]
