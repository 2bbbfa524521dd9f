"""Two hosts on this machine for the lab-network tests: network namespaces joined by a veth pair
(addresses inside 10.231.x only), and processes started inside one. Needs root and iproute2."""

from __future__ import annotations

import os
import random
import shutil
import subprocess
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path

import pytest

from support.rosgraph import Process


def ip(*args: str) -> None:
    subprocess.run(["ip", *args], check=True, capture_output=True, timeout=10)


@contextmanager
def lab_hosts() -> Iterator[tuple[str, str, str]]:
    """Two network namespaces joined by a veth pair; yields (nsA, nsB, ifA); skips the calling
    test without root or ``ip``."""
    if os.geteuid() != 0 or shutil.which("ip") is None:
        pytest.skip("needs root and iproute2 to make network namespaces")
    tag = f"{os.getpid() % 10000}{random.randint(0, 99)}"
    a, b, va, vb = f"hapA{tag}", f"hapB{tag}", f"hva{tag}", f"hvb{tag}"
    subnet = random.randint(1, 250)
    try:
        ip("netns", "add", a)
        ip("netns", "add", b)
        ip("link", "add", va, "type", "veth", "peer", "name", vb)
        ip("link", "set", va, "netns", a)
        ip("link", "set", vb, "netns", b)
        ip("-n", a, "addr", "add", f"10.231.{subnet}.1/24", "dev", va)
        ip("-n", b, "addr", "add", f"10.231.{subnet}.2/24", "dev", vb)
        for ns, dev in ((a, va), (b, vb)):
            ip("-n", ns, "link", "set", "lo", "up")
            ip("-n", ns, "link", "set", dev, "up")
        yield a, b, va
    finally:
        for ns in (a, b):
            subprocess.run(["ip", "netns", "del", ns], capture_output=True)


def in_ns(ns: str, argv: list[str], env: dict[str, str], log: Path) -> Process:
    """``argv`` started inside network namespace ``ns`` (logging to ``log``)."""
    return Process(["ip", "netns", "exec", ns, *argv], env, log)
