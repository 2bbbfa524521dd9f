"""The one error type of bag reading and analysis: a problem with the user's bag or options."""

from __future__ import annotations

from haptic_dob.errors import InputError


class BagError(InputError):
    """A bag that cannot be analysed as asked (missing, corrupt, wrong topics, too short...).

    The message names the bag and the problem in one line; ``haptic-analyze`` prints it as
    ``ERROR: ...`` and exits with code 2.
    """
