"""Write constraints.txt from a ``pip install --dry-run --report`` JSON (used by ``make lock``)."""

from __future__ import annotations

import json
import sys

HEADER = """# Exact versions of every distribution `make install` resolves, and of the optional
# `arms` extra (pip constraints file).
# Regenerate after changing dependencies with `make lock` and review the diff.
"""


def main(report: str, out: str) -> int:
    """Read the report, drop the project itself, write sorted ``name==version`` lines."""
    with open(report, encoding="utf-8") as fh:
        data = json.load(fh)
    lines = sorted(
        (
            f"{i['metadata']['name']}=={i['metadata']['version']}"
            for i in data["install"]
            if i["metadata"]["name"].lower() != "haptic-dob"
        ),
        key=str.lower,
    )
    with open(out, "w", encoding="utf-8") as fh:
        fh.write(HEADER + "\n".join(lines) + "\n")
    print(f"{out}: {len(lines)} pinned distributions")
    return 0


if __name__ == "__main__":
    sys.exit(main(*sys.argv[1:3]))
