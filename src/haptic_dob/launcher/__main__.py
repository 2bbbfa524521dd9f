"""``python -m haptic_dob.launcher``: the same as ``haptic-launch``."""

import sys

from haptic_dob.cli.launch import main

if __name__ == "__main__":
    sys.exit(main())
