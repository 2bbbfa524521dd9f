"""PNG figures of an analysed segment (matplotlib, Agg backend: no display needed).

Per segment, three files named ``<bag>_seg<i>_<kind>.png``:

- ``transparency``: |T| in dB over frequency with the +-3 dB band and the bandwidth marked;
- ``error``: normalized impedance error |Z_d - Z_hat| / |Z_d| (%) over frequency, band shaded;
- ``traces``: position, hand force and the passivity-observer energy over stamp time (long
  records are drawn from at most ``MAX_POINTS`` min/max-decimated points).
"""

from __future__ import annotations

import re
from pathlib import Path
from typing import Any

import numpy as np

from haptic_dob.analysis.transparency import BAND_DB
from haptic_dob.bag.results import BagAnalysis, SegmentResult

MAX_POINTS = 20_000


def _decimate(t: np.ndarray, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """At most ``MAX_POINTS`` points keeping each block's min and max (the envelope shows)."""
    if y.size <= MAX_POINTS:
        return t, y
    block = int(np.ceil(y.size / (MAX_POINTS // 2)))
    n = y.size // block * block
    yb = y[:n].reshape(-1, block)
    tb = t[:n].reshape(-1, block)
    lo, hi = yb.argmin(axis=1), yb.argmax(axis=1)
    rows = np.arange(yb.shape[0])
    first = np.minimum(lo, hi)
    second = np.maximum(lo, hi)
    tt = np.column_stack((tb[rows, first], tb[rows, second])).ravel()
    yy = np.column_stack((yb[rows, first], yb[rows, second])).ravel()
    return tt, yy


def _stem(bag: str) -> str:
    name = Path(bag.rstrip("/")).name or "bag"
    return re.sub(r"[^A-Za-z0-9_.-]+", "_", name)


def write_plots(analyses: list[BagAnalysis], directory: str | Path) -> list[Path]:
    """Write every segment's figures into ``directory`` (created); returns the files."""
    import matplotlib  # lazy: the Agg backend is chosen before pyplot loads

    matplotlib.use("Agg")
    out = Path(directory)
    out.mkdir(parents=True, exist_ok=True)
    files: list[Path] = []
    used: set[str] = set()
    for a in analyses:
        stem = _stem(a.path)
        base, i = stem, 2
        while stem in used:  # two bags with the same name
            stem, i = f"{base}_{i}", i + 1
        used.add(stem)
        for r in a.segments:
            files += _segment_plots(r, out / f"{stem}_seg{r.segment.index}")
    return files


def _segment_plots(r: SegmentResult, prefix: Path) -> list[Path]:
    import matplotlib.pyplot as plt  # lazy: after write_plots chose the Agg backend

    files = []
    title = f"{Path(r.bag).name} segment {r.segment.index}: {r.label}"
    tr = r.figures.transparency
    if tr is not None:
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.semilogx(tr.freqs_hz, tr.magnitude_db, "o-", ms=3, label="|T| = |Z_hat / Z_d|")
        ax.axhspan(-BAND_DB, BAND_DB, color="tab:green", alpha=0.12, label="+-3 dB")
        ax.axvline(
            tr.bandwidth_hz, color="tab:red", ls="--", label=f"bandwidth {tr.bandwidth_hz:.2f} Hz"
        )
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("|T| (dB)")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        files.append(_save(fig, prefix.with_name(prefix.name + "_transparency.png")))
        fig, ax = plt.subplots(figsize=(7, 4))
        ax.semilogx(tr.freqs_hz, tr.error_per_bin * 100.0, "o-", ms=3)
        ax.axvspan(
            tr.freqs_hz[0],
            tr.bandwidth_hz,
            color="tab:green",
            alpha=0.12,
            label=f"inside the band: mean {tr.impedance_error_pct:.1f} %",
        )
        ax.set_xlabel("frequency (Hz)")
        ax.set_ylabel("|Z_d - Z_hat| / |Z_d| (%)")
        ax.set_title(title, fontsize=9)
        ax.grid(True, which="both", alpha=0.3)
        ax.legend(fontsize=8)
        files.append(_save(fig, prefix.with_name(prefix.name + "_error.png")))
    rec, w = r.record, r.window
    t = np.asarray(rec.time_s(np.arange(w.start, w.stop)))
    fig, axes = plt.subplots(3, 1, figsize=(8, 7), sharex=True)
    for ax, y, label in (
        (axes[0], rec.x[w] * 1e3, "position (mm)"),
        (axes[1], rec.force[w], "hand force (N)"),
        (axes[2], r.figures.energy.energy_in_j * 1e3, "energy into the device (mJ)"),
    ):
        tt, yy = _decimate(t, y)
        ax.plot(tt, yy, lw=0.6)
        ax.set_ylabel(label)
        ax.grid(True, alpha=0.3)
    axes[2].axhline(0.0, color="k", lw=0.5)
    axes[2].set_xlabel("stamp time (s)")
    axes[0].set_title(title, fontsize=9)
    files.append(_save(fig, prefix.with_name(prefix.name + "_traces.png")))
    return files


def _save(fig: Any, path: Path) -> Path:
    import matplotlib.pyplot as plt  # lazy: after write_plots chose the Agg backend

    fig.tight_layout()
    fig.savefig(path, dpi=100)
    plt.close(fig)
    return path
