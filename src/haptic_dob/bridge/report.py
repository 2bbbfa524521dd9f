"""What the bridge reports: its ``/diagnostics`` status and, at shutdown, its stats file."""

from __future__ import annotations

import json
import math
from collections.abc import Callable, Mapping
from typing import Any

from haptic_dob.bridge.loop import BridgeLoop
from haptic_dob.runtime.status import Status


def bridge_status(
    loop: BridgeLoop, authority: Mapping[str, Any], refusing_foreign: Callable[[], bool]
) -> Status:
    """The bridge's counts (floats to two decimals) and the command authority's; a warning while
    the driver gets zero (``BridgeLoop.status``) or when ``refusing_foreign()`` (commands of
    publishers not the loop's were refused since the last report; asked only when the loop's
    commands pass)."""
    values = {k: (f"{x:.2f}" if isinstance(x, float) else x) for k, x in loop.counts().items()}
    values.update(authority)
    why = loop.status()
    if why:
        return Status(True, f"{why}: zero command", values)
    if refusing_foreign():
        return Status(True, "refused commands from a publisher not the loop's", values)
    return Status(False, "running", values)


def write_stats(path: str, counts: Mapping[str, float]) -> None:
    """Write the bridge's ``counts`` to ``path`` as JSON, a NaN (nothing measured) as null."""
    clean = {k: (None if isinstance(x, float) and math.isnan(x) else x) for k, x in counts.items()}
    with open(path, "w", encoding="utf-8") as fh:
        json.dump(clean, fh, indent=2)
