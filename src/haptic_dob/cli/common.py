"""Shared plumbing of the command-line tools: typed errors become one ``ERROR:`` line and exit 2.

Every tool is built in three layers (like rosbags' ``convert``): a library function that raises,
``command(...) -> int`` that turns ``ValueError``/``OSError``/``InputError`` into ``ERROR: ...`` on
stderr and an exit code, and a few lines of argparse in ``main()``.
"""

from __future__ import annotations

import argparse
import os
import sys
import traceback
from collections.abc import Callable
from typing import NoReturn

from haptic_dob.errors import InputError

EXIT_OK = 0
EXIT_INTERNAL = 1
EXIT_ERROR = 2
EXIT_INTERRUPTED = 130


class ArgumentParser(argparse.ArgumentParser):
    """argparse with the project's error format: ``ERROR: ...`` plus usage, exit 2."""

    def error(self, message: str) -> NoReturn:
        self.print_usage(sys.stderr)
        self.exit(EXIT_ERROR, f"ERROR: {message}\n")


def run(fn: Callable[[], int | None]) -> int:
    """Call ``fn``; map expected failures to ``ERROR:`` lines and exit codes (no tracebacks)."""
    try:
        return int(fn() or EXIT_OK)
    except KeyboardInterrupt:
        print("interrupted", file=sys.stderr)
        return EXIT_INTERRUPTED
    except BrokenPipeError:  # the reader went away (``| head``): stop quietly
        sys.stdout = open(os.devnull, "w")  # noqa: SIM115 - nothing more may reach the pipe
        return EXIT_OK
    except (InputError, ValueError, OSError) as exc:
        print(f"ERROR: {_one_line(exc)}", file=sys.stderr)
        return EXIT_ERROR
    except Exception as exc:  # a bug: say so in one line, the traceback on request
        if os.environ.get("HAPTIC_DOB_DEBUG"):
            traceback.print_exc()
        print(
            f"ERROR: internal error ({type(exc).__name__}: {_one_line(exc)}); "
            "set HAPTIC_DOB_DEBUG=1 for the traceback and please report it",
            file=sys.stderr,
        )
        return EXIT_INTERNAL


def _one_line(exc: BaseException) -> str:
    text = str(exc) or type(exc).__name__
    if isinstance(exc, OSError) and exc.filename and exc.strerror:
        text = f"{exc.strerror}: {exc.filename}"
    return " ".join(text.split())


def parse_range(text: str, name: str) -> list[float]:
    """``FROM:TO:STEP`` (inclusive of TO within half a step) to a list of floats."""
    parts = text.split(":")
    try:
        lo, hi, step = (float(p) for p in parts)
    except ValueError:
        raise InputError(f"{name} must be FROM:TO:STEP (numbers), got {text!r}") from None
    if not (lo > 0 and hi >= lo and step > 0):
        raise InputError(f"{name} needs 0 < FROM <= TO and STEP > 0, got {text!r}")
    n = int((hi - lo) / step + 0.5) + 1
    if n > 10_000:
        raise InputError(f"{name} gives {n} points; at most 10000")
    return [lo + i * step for i in range(n)]
