#!/usr/bin/env python3
"""Analyse recorded haptic sessions: the same program as the ``haptic-analyze`` command.

    scripts/haptic_analyze.py BAG [BAG ...] [--json | --csv] [--plot DIR] ...

See ``haptic-analyze --help`` (``haptic_dob.cli.analyze``).
"""

import sys

from haptic_dob.cli.analyze import main

if __name__ == "__main__":
    sys.exit(main())
