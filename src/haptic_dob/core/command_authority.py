"""Command authority at the device end, ROS-free: which effort commands from other processes move
the device.

A command handed over in this process comes from the loop's own controller (the loop composed)
and is not checked here. A command from another process moves the device only when its layout
label carries the expected token (``effort@<stamp>#<token>``): the session's ``command_token``
(``haptic-launch`` writes a fresh one for a device and its controller at every launch) or, when
the device has none, the token of the named command source's commands, taken from the first one
that arrives while the middleware's graph shows that node as the only publisher of the topic
outside this process (taken again when its endpoint GIDs change: a restarted controller). While a
publisher of the topic is in this process, a command from elsewhere with its token is the
middleware's copy of one already taken: dropped. Every other command is refused (counted, each
publisher named once, when the graph lists it) unless the input is open (bench work): then it
is taken. Not authentication: docs/safety.md says what this does and does not keep out.
"""

from __future__ import annotations

import math
import secrets
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Protocol

#: the graph is looked at again on a refusal when this long passed since the last look (s), or
#: when the number of matched publishers changed
LOOK_AGAIN_S = 1.0
#: a publisher the graph knows by its GID alone (its node's name not discovered yet) is named by
#: its GID once this long passed (s) since its first refused command
NAME_GRACE_S = 2.0


def new_token() -> str:
    """A fresh command token: 16 hex digits (64 random bits)."""
    return secrets.token_hex(8)


@dataclass(frozen=True)
class Endpoint:
    """A publisher as the middleware reports it: its node (fully qualified; '' while the graph
    does not know it yet) and endpoint GID."""

    node: str
    gid: str


class Graph(Protocol):
    """What the authority asks the middleware about the command topic."""

    def matched(self) -> int:
        """Publishers the input has matched now (cheap: asked on refusals)."""

    def publishers(self) -> Sequence[Endpoint]:
        """The topic's publishers outside this process, as the graph shows them now."""

    def unlisted(self) -> int:
        """Publishers the input had matched that the last ``publishers()`` did not list (the
        graph not told of them yet)."""


class Verdict(Enum):
    """What becomes of a command from another process."""

    TAKE = "take"  # it moves the device
    COPY = "copy"  # the middleware's copy of a command taken in process: dropped
    REFUSE = "refuse"  # refused: counted, its publisher named once


def _quiet(_text: str) -> None:
    return None


class CommandAuthority:
    """Decides, per command from another process, whether it moves the device (``admit``).

    Args:
        source: the command source's fully qualified node name (``/ns/controller_node``).
        graph: the middleware's view of the command topic.
        token: the session's command token ('' = learn the source's from the graph).
        open_input: take commands from any publisher (bench work).
        warn, info: where refusals and learnt tokens are said (default: nowhere).
        clock: monotonic seconds (for how fresh the graph's view is).
    """

    def __init__(
        self,
        source: str,
        graph: Graph,
        token: str = "",
        open_input: bool = False,
        warn: Callable[[str], object] = _quiet,
        info: Callable[[str], object] = _quiet,
        clock: Callable[[], float] = time.monotonic,
    ) -> None:
        self.source = source
        self.graph = graph
        self.token = token
        self.expected = token  # the token a command from elsewhere must carry ('' = none yet)
        self.open_input = open_input
        self.refused = 0  # commands refused
        self.taken = 0  # commands of other publishers taken (open input)
        self.named: dict[str, str] = {}  # GID -> node of every publisher said so far
        self._pending: dict[str, tuple[float, bool]] = {}  # GID -> (first refusal, taken?)
        self.strangers: tuple[Endpoint, ...] = ()  # outside publishers not named as the source
        self.source_gids: frozenset[str] = frozenset()  # the source's endpoints outside
        self._learnt_from: frozenset[str] | None = None  # the source's GIDs when it was learnt
        self._warn, self._info, self._clock = warn, info, clock
        self._looked_at = -math.inf
        self._looked_matched = -1
        self._outside: frozenset[str] = frozenset()
        self._unnamed_said = False
        self._unlisted = 0  # matched publishers the last look did not list
        #: a refusal came while some were unlisted: (when, taken?, the GIDs listed then, found?)
        self._awaiting: tuple[float, bool, frozenset[str], bool] | None = None

    @property
    def mode(self) -> str:
        """How commands from other processes are checked, in words."""
        if self.open_input:
            return "open to any publisher (open_command_input)"
        if self.token:
            return f"session token (command_token), from {self.source}"
        if self.expected:
            return f"{self.source}'s token, taken while the graph showed it alone"
        return f"waiting for {self.source} alone in the graph"

    def admit(self, token: str, here: str = "") -> Verdict:
        """The verdict on a command from another process carrying ``token`` ('' = none);
        ``here`` is the token of the commands handed over in this process ('' = none)."""
        if token:
            if token == here:
                return Verdict.COPY
            if token == self.expected:
                return Verdict.TAKE
        self._look()
        if token and not self.token and self._may_learn():
            self.expected = token
            self._learnt_from = self.source_gids
            gids = ", ".join(sorted(self.source_gids))
            self._info(
                f"taking effort_command from {self.source} (GID {gids}): the graph shows it as "
                "the only publisher from elsewhere (no command_token)"
            )
            return Verdict.TAKE
        if self.open_input:
            self.taken += 1
            self._name(taking=True)
            return Verdict.TAKE
        self.refused += 1
        self._name(taking=False)
        return Verdict.REFUSE

    def follow_up(self) -> None:
        """Name the publishers whose commands came while the graph did not know their node yet
        (call it now and then): once the graph knows it, or by the GID after ``NAME_GRACE_S``;
        and those matched but not listed at a refusal, once the graph lists them."""
        if not self._pending and self._awaiting is None:
            return
        self._look(force=True)
        now = self._clock()
        if self._awaiting is not None:
            self._follow_unlisted(now, *self._awaiting)
        strangers = {e.gid: e for e in self.strangers}
        for gid, (first, taking) in list(self._pending.items()):
            e = strangers.get(gid)
            if e is None and gid in self.source_gids:  # it was the source, named late
                del self._pending[gid]
            elif e is None or e.node or now - first >= NAME_GRACE_S:
                del self._pending[gid]
                self._say(e or Endpoint("", gid), taking)

    # --- the graph ------------------------------------------------------------------------
    def _look(self, force: bool = False) -> None:
        """Look at the graph again when the matched publishers changed or the view is old."""
        matched = self.graph.matched()
        now = self._clock()
        fresh = matched == self._looked_matched and now - self._looked_at < LOOK_AGAIN_S
        if fresh and not force:
            return
        self._looked_matched, self._looked_at = matched, now
        outside = tuple(self.graph.publishers())
        self.strangers = tuple(e for e in outside if e.node != self.source)
        self.source_gids = frozenset(e.gid for e in outside if e.node == self.source)
        self._unlisted = self.graph.unlisted()
        gids = frozenset(e.gid for e in outside)
        if gids != self._outside:
            self._outside = gids
            self._unnamed_said = False

    def _may_learn(self) -> bool:
        """The source alone publishes from elsewhere, every matched publisher is it, and it is
        not the one whose token is expected already (a restarted source has new GIDs)."""
        return (
            bool(self.source_gids)
            and not self.strangers
            and self.graph.matched() == len(self.source_gids)
            and self.source_gids != self._learnt_from
        )

    def _name(self, taking: bool) -> None:
        """Say each publisher a command was refused (or, open, taken) from, once; one the graph
        knows by its GID alone waits for ``follow_up``."""
        self._name_each(self.strangers, self._clock(), taking)
        if self._unlisted > 0:  # the sender may be one the graph does not list yet
            if self._awaiting is None:
                self._awaiting = (self._clock(), taking, self._outside, False)
        elif not self.strangers and not taking:
            self._say_unnamed()

    def _follow_unlisted(
        self, now: float, first: float, taking: bool, known: frozenset[str], found: bool
    ) -> None:
        """Name the publishers the graph listed since a refusal found some unlisted. One that
        left unlisted, or is still unlisted after ``NAME_GRACE_S``, is said not to be named."""
        found = found or bool(self._outside - known)  # listed since (the source's too)
        self._name_each([e for e in self.strangers if e.gid not in known], first, taking)
        done = self._unlisted == 0 or now - first >= NAME_GRACE_S
        self._awaiting = None if done else (first, taking, known, found)
        if done and not taking and (self._unlisted > 0 or not found):
            self._say_unnamed()

    def _name_each(self, endpoints: Sequence[Endpoint], first: float, taking: bool) -> None:
        """Say each of ``endpoints`` not said yet; one known by its GID alone waits, from
        ``first``, for ``follow_up``."""
        for e in endpoints:
            if e.gid in self.named or e.gid in self._pending:
                continue
            if e.node:
                self._say(e, taking)
            else:
                self._pending[e.gid] = (first, taking)

    def _say_unnamed(self) -> None:
        """Say once (per change of the graph's publishers) that a refused command's publisher
        cannot be named."""
        if self._unnamed_said:
            return
        self._unnamed_said = True
        named_as_source = ", ".join(sorted(self.source_gids)) or "none now"
        self._warn(
            "refused effort_command without the expected token from a publisher the graph "
            f"does not tell apart by name (gone already, not listed yet, or named {self.source}: "
            f"GIDs {named_as_source}); counted in /diagnostics"
        )

    def _say(self, e: Endpoint, taking: bool) -> None:
        node = e.node or "a publisher whose node the graph does not name"
        self.named[e.gid] = node
        if taking:
            self._info(f"taking effort_command from {node} (GID {e.gid}): open_command_input")
        else:
            self._warn(
                f"refused effort_command from {node} (GID {e.gid}): only {self.source}'s "
                "commands move this device (they carry the session's command token); counted in "
                "/diagnostics, said once per publisher; open_command_input opens the input for "
                "bench work"
            )
