"""The generated parameter reference is current (regenerate with scripts/param_docs.py)."""

from __future__ import annotations

import subprocess
import sys


def test_parameter_docs_are_current(root) -> None:
    out = subprocess.run(
        [sys.executable, str(root / "scripts" / "param_docs.py"), "--check"],
        capture_output=True,
        text=True,
        timeout=120,
    )
    assert out.returncode == 0, out.stderr
