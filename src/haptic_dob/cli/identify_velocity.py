"""``haptic-identify BAG --velocity-noise --counts C``: the bridge's Kalman velocity filter.

Fits the jerk density of ``haptic_dob.identification.velocity_noise`` to a recorded session's
joint positions (the hand on the device), prints it, and writes the bridge's params file
(``state.velocity_jerk_psd``, and ``state.encoder_resolution`` when every joint was read) with
``--write-yaml``.
"""

from __future__ import annotations

import json
from collections.abc import Sequence
from pathlib import Path

from haptic_dob.bag.joints import read_joints
from haptic_dob.errors import InputError
from haptic_dob.identification.filters import IdentificationError
from haptic_dob.identification.velocity_noise import MIN_COUNTS, JerkFit, identify_jerk_psd
from haptic_dob.runtime.params_file import dump_params


def parse_counts(text: str) -> tuple[float, ...]:
    """``--counts``: one positive count, or one per joint, comma-separated (position units)."""
    try:
        counts = tuple(float(c) for c in text.split(","))
    except ValueError:
        counts = ()
    if not counts or not all(0.0 < c < float("inf") for c in counts):
        raise InputError(
            f"--counts needs positive numbers, one or one per joint (4e-4,4e-4,8e-4), got {text!r}"
        )
    return counts


def velocity_table(fit: JerkFit, bag: str, names: Sequence[str], counts: Sequence[float]) -> str:
    """The density, then each joint's count, span in counts and whether it was fitted."""
    rows = [
        f"bag {bag}: the Kalman velocity filter's jerk density, period {1e3 * fit.period_s:.4g} ms",
        f"velocity_jerk_psd (units^2/s^5)  {fit.psd:.4g}",
        "joint                count        span (counts)  fitted",
    ]
    for name, count, span in zip(names, counts, fit.spans_counts, strict=True):
        used = "yes" if name in fit.fitted else f"no (under {MIN_COUNTS} counts)"
        rows.append(f"{name:<20} {count:<12.4g} {span:<14.0f} {used}")
    return "\n".join(rows)


def velocity_yaml(fit: JerkFit, counts: Sequence[float] | None, bag: str) -> str:
    """The bridge's params file: the density for every joint, and the counts the fit took
    where they are every joint's (None: the config's stay)."""
    head = (
        f"# identified from {bag} by haptic-identify --velocity-noise (joints fitted: "
        f"{', '.join(fit.fitted)}); load after the bridge's config\n"
    )
    state: dict[str, list[float]] = {}
    if counts is not None:
        state["state.encoder_resolution"] = list(counts)
    state["state.velocity_jerk_psd"] = [float(f"{fit.psd:.6g}")]
    return head + dump_params({"/**/bridge_node": {"ros__parameters": state}})


def velocity_command(
    bag: str,
    topic: str,
    joints: Sequence[str],
    counts_text: str,
    as_json: bool,
    write_yaml: str | None,
) -> int:
    """Identify the density, print it, optionally write the bridge's params file."""
    counts = parse_counts(counts_text)
    js = read_joints(bag, topic, joints or None, need_effort=False)
    n = len(js.names)
    if len(counts) not in (1, n):
        raise InputError(f"--counts: give 1 or {n} (one per joint: {', '.join(js.names)})")
    per_joint = counts * n if len(counts) == 1 else counts
    try:
        fit = identify_jerk_psd(js.stamps_ns, js.position, js.names, per_joint)
    except IdentificationError as exc:
        raise InputError(f"{bag}: {exc}") from None
    if as_json:
        print(json.dumps({"bag": bag, "joints": list(js.names), **fit.__dict__}))
    else:
        print(velocity_table(fit, bag, js.names, per_joint))
    if write_yaml:
        # the counts of some joints only are not the bridge's list: the density alone then
        every = None if joints else per_joint
        Path(write_yaml).write_text(velocity_yaml(fit, every, bag), encoding="utf-8")
        if not as_json:
            print(f"bridge params written to {write_yaml}")
    return 0
