"""The DDS domain and discovery range a process runs with, read from its environment (ROS-free):
what ``haptic-launch`` prints, and the start-up check a real device's node makes.

They are read as rcl reads them: ``ROS_DOMAIN_ID`` (unset: 0), ``ROS_AUTOMATIC_DISCOVERY_RANGE``
(unset: ``SUBNET``; a value other than ``OFF``, ``LOCALHOST``, ``SUBNET``, ``SYSTEM_DEFAULT``:
``LOCALHOST``), ``ROS_STATIC_PEERS`` (hosts discovered by name, ``;``-separated), and the
deprecated ``ROS_LOCALHOST_ONLY=1``, which prevails over both. ``exposure`` is the one-line
warning for a real device on the default domain, or discovering beyond this host with no peers
list: anyone on the network who runs ROS 2 with no settings of their own shares domain 0.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass

DEFAULT_DOMAIN = "0"
RANGES = ("LOCALHOST", "SUBNET", "OFF", "SYSTEM_DEFAULT")


@dataclass(frozen=True)
class Discovery:
    """A process's DDS domain and discovery settings."""

    domain: str  # ROS_DOMAIN_ID as given ("0" when unset)
    domain_given: bool  # ROS_DOMAIN_ID is set
    range: str  # LOCALHOST, SUBNET, OFF or SYSTEM_DEFAULT
    peers: tuple[str, ...]  # ROS_STATIC_PEERS

    @classmethod
    def of(cls, env: Mapping[str, str]) -> Discovery:
        """The settings ``env`` (a process's environment) gives."""
        domain = env.get("ROS_DOMAIN_ID", "")
        if env.get("ROS_LOCALHOST_ONLY", "").startswith("1"):
            return cls(domain or DEFAULT_DOMAIN, bool(domain), "LOCALHOST", ())
        given = env.get("ROS_AUTOMATIC_DISCOVERY_RANGE", "")
        found = (given if given in RANGES else "LOCALHOST") if given else "SUBNET"
        peers: tuple[str, ...] = ()
        if found != "OFF":
            peers = tuple(p for p in env.get("ROS_STATIC_PEERS", "").split(";") if p)
        return cls(domain or DEFAULT_DOMAIN, bool(domain), found, peers)

    @property
    def default_domain(self) -> bool:
        """The domain is ROS 2's default (0), which every session without settings shares."""
        return self.domain.lstrip("0") == ""

    @property
    def beyond_host(self) -> bool:
        """Discovery reaches other hosts (``SUBNET`` or ``SYSTEM_DEFAULT``)."""
        return self.range not in ("LOCALHOST", "OFF")

    def describe(self) -> str:
        """``domain 42, discovery localhost`` (with the default and the peers said)."""
        domain = f"domain {self.domain}" + (
            "" if self.domain_given else " (ROS_DOMAIN_ID unset: the default)"
        )
        text = f"{domain}, discovery {self.range.lower()}"
        if self.peers:
            text += f", peers {', '.join(self.peers)}"
        return text

    def exposure(self) -> str | None:
        """The one-line warning for a real device, or None when its settings keep it apart."""
        reasons = []
        if self.default_domain:
            reasons.append("the default domain 0, which every ROS 2 session without settings uses")
        if self.beyond_host and not self.peers:
            reasons.append(f"discovery {self.range.lower()} with no ROS_STATIC_PEERS list")
        if not reasons:
            return None
        return (
            f"a real device on {' and '.join(reasons)}: a stray ros2 topic pub elsewhere on the "
            "network can reach effort_command (refused unless it carries the session's command "
            "token, but not kept out); set ROS_DOMAIN_ID and ROS_AUTOMATIC_DISCOVERY_RANGE="
            "LOCALHOST, or name the peers (docs/running.md, Lab network and security)"
        )


def exposure_warning(env: Mapping[str, str]) -> str | None:
    """The start-up warning a real device's node says for its environment ``env``, or None."""
    return Discovery.of(env).exposure()
