"""Calling a console entry point's ``main`` in process, as its shell would see it."""

from __future__ import annotations

from collections.abc import Callable, Sequence


def exit_code(main: Callable[[Sequence[str]], int], argv: Sequence[str]) -> int:
    """``main(argv)``'s exit status: what it returns, or argparse's ``SystemExit`` code."""
    try:
        return main(argv)
    except SystemExit as exc:  # argparse's refusals
        return int(exc.code or 0)
