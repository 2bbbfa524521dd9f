"""``LoopLog``: the lines rclpy's logger says, said without rclpy's per-call source lookups.

Each case runs in a process of its own (rcutils writes to the process's stderr, formatted by
``RCUTILS_CONSOLE_OUTPUT_FORMAT``); no DDS is involved.
"""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap

#: the caller's function, file and line in every line, so both loggers' can be compared
FORMAT = "[{severity}] [{name}] {function_name} {file_name}:{line_number}: {message}"


def run(body: str, *, level: str = "", stdout: str | None = None) -> list[str]:
    """Run ``body`` (``log``: a LoopLog, ``ros``: its rclpy logger) and return its stderr lines;
    ``stdout``: what it must print."""
    script = textwrap.dedent(
        """
        import time
        import rclpy.logging
        from haptic_dob.runtime.ros.log import LoopLog
        ros = rclpy.logging.get_logger("loop_log_test")
        log = LoopLog(ros)
        """
    ) + textwrap.dedent(body)
    env = dict(os.environ, RCUTILS_CONSOLE_OUTPUT_FORMAT=FORMAT, RCUTILS_COLORIZED_OUTPUT="0")
    if level:
        script = script.replace(
            "log = LoopLog(ros)",
            f"ros.set_level(rclpy.logging.LoggingSeverity.{level})\nlog = LoopLog(ros)",
        )
    out = subprocess.run(
        [sys.executable, "-c", script], env=env, capture_output=True, text=True, timeout=60
    )
    assert out.returncode == 0, out.stderr
    if stdout is not None:
        assert out.stdout == stdout, out.stdout
    return out.stderr.splitlines()


def test_a_line_is_the_line_rclpy_says_from_the_same_call_site() -> None:
    """Both loggers called from one function on one line: the same severity, name, function,
    file, line and message."""
    lines = run(
        """
        def here(logger):
            logger.warning("the watchdog tripped")
        here(ros)
        here(log)
        """
    )
    assert len(lines) == 2, lines
    assert lines[0] == lines[1], lines
    assert lines[0].startswith("[WARN] [loop_log_test] here "), lines
    assert lines[0].endswith("<string>:9: the watchdog tripped"), lines


def test_a_method_handed_over_as_a_callback_names_the_code_that_calls_it() -> None:
    """``warn=log.warning`` given to a core object (the controller's command join): the line
    names the core's function and line, as rclpy's own bound method does."""
    lines = run(
        """
        class Join:
            def __init__(self, warn):
                self.warn = warn
            def fall_back(self):
                self.warn("input late: fallback")
        Join(ros.warning).fall_back()
        Join(log.warning).fall_back()
        """
    )
    assert len(lines) == 2 and lines[0] == lines[1], lines
    assert " fall_back " in lines[0] and "<string>:" in lines[0], lines


def test_each_severity_is_said_as_rclpy_names_it() -> None:
    lines = run(
        """
        log.info("i")
        log.warning("w")
        log.error("e")
        log.debug("not said at the default level")
        """
    )
    assert [ln.split(" ", 1)[0] for ln in lines] == ["[INFO]", "[WARN]", "[ERROR]"], lines


def test_a_logger_level_silences_what_is_below_it() -> None:
    lines = run(
        """
        print(log.info("below"), log.error("above"), flush=True)
        """,
        level="ERROR",
        stdout="False True\n",
    )
    assert lines == [lines[0]] and lines[0].endswith(": above"), lines


def test_a_throttled_call_site_says_once_per_period_and_sites_are_apart() -> None:
    """Three calls from one site within 5 s say one line; another site says its own; a site
    whose period has passed says again."""
    lines = run(
        """
        def tripped(n):
            return log.warning(f"trip {n}", throttle_duration_sec=5.0)
        def resumed():
            return log.info("resumed", throttle_duration_sec=0.05)
        said = [tripped(1), tripped(2), resumed(), tripped(3), resumed()]
        time.sleep(0.1)
        said.append(resumed())
        assert said == [True, False, True, False, False, True], said
        """
    )
    assert [ln.rsplit(": ", 1)[1] for ln in lines] == ["trip 1", "resumed", "resumed"], lines


def test_filters_other_than_the_throttle_and_bad_periods_are_refused() -> None:
    run(
        """
        for kwargs, error in (({"once": True}, TypeError),
                              ({"throttle_duration_sec": -1.0}, ValueError),
                              ({"throttle_duration_sec": float("nan")}, ValueError)):
            try:
                log.warning("x", **kwargs)
            except error:
                continue
            raise SystemExit(f"{kwargs} was taken")
        """
    )
