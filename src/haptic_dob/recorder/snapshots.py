"""Parameter snapshots: which nodes the recorder asks for their parameters, and how far each is.

Every node of the recorder's namespaces (its own, or those it is given: a teleoperation graph's
``/master`` and ``/slave``; not hidden ones nor the recorder) is asked once,
when it appears: ``list_parameters``, then ``get_parameters`` of every name. A node silent for
the timeout is reported once and still asked: the question goes again every timeout, the earlier
requests kept waiting (up to ``MAX_ASKED``), and the first answer counts. A loaded node answers
late, and rmw_fastrtps drops a response for good when the node has not matched the asking
client's response reader within 100 ms of answering (ros2/rmw_fastrtps#390), as happens right
after discovery on a loaded machine. The recorder keeps its clients until the node answered (a
client dropped under a pending request makes the node's own executor fail to send its response).
Until a node
answered or timed out, the progress the recorder reports is held where that node appeared, so
a short lockstep run cannot end before the bag knows the session's parameters.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Sequence
from dataclasses import dataclass, field
from typing import Any, Generic, Protocol, TypeVar


class ServiceClient(Protocol):
    """The part of an rclpy service client the snapshots use."""

    def service_is_ready(self) -> bool:
        """Whether the service is there."""
        ...

    def call_async(self, request: Any) -> Any:
        """Send ``request``; a future with ``done()`` and ``result()`` (None: the call failed)."""
        ...

    def remove_pending_request(self, future: Any) -> None:
        """Forget the request of ``future`` (asked again instead)."""
        ...


C = TypeVar("C", bound=ServiceClient)

#: requests of one question kept waiting for an answer at once (the oldest is dropped for a new)
MAX_ASKED = 4


@dataclass
class ParameterSnapshot:
    """All parameters of one node: names and their ``rcl_interfaces/msg/ParameterValue``."""

    node: str
    names: list[str]
    values: list[Any]


@dataclass
class PendingSnapshot(Generic[C]):
    """A node whose parameters are being asked for."""

    node: str  # fully qualified name
    started_s: float  # when it appeared (monotonic, s)
    progress_ns: int  # the recorder's progress then
    list_client: C
    get_client: C
    futures: list[Any] = field(default_factory=list)  # of the question, asked (again) so far
    asked_s: float = 0.0  # when it was last asked (monotonic, s)
    names: list[str] | None = None  # once listed
    warned: bool = False  # timed out (and reported)


@dataclass
class SnapshotRound(Generic[C]):
    """What one round of asking brought."""

    answered: list[ParameterSnapshot] = field(default_factory=list)
    ended: list[PendingSnapshot[C]] = field(default_factory=list)  # answered or failed


class SnapshotTracker(Generic[C]):
    """The nodes of ``namespaces`` (one, or several) whose parameters the recorder ``own_name``
    asks for.

    ``list_request()`` and ``get_request(names)`` make the two service requests.
    """

    def __init__(
        self,
        own_name: str,
        namespaces: str | Sequence[str],
        timeout_s: float,
        list_request: Callable[[], Any],
        get_request: Callable[[list[str]], Any],
    ) -> None:
        self.namespaces = (namespaces,) if isinstance(namespaces, str) else tuple(namespaces)
        self.timeout_s = timeout_s
        self.pending: list[PendingSnapshot[C]] = []
        self._known = {own_name}
        self._list_request = list_request
        self._get_request = get_request

    def appeared(self, names_and_namespaces: Iterable[tuple[str, str]]) -> list[str]:
        """Fully qualified names of the nodes of the namespaces not seen before (not hidden)."""
        new = []
        for name, space in names_and_namespaces:
            full = f"{space.rstrip('/')}/{name}"
            if space not in self.namespaces or name.startswith("_") or full in self._known:
                continue
            self._known.add(full)
            new.append(full)
        return new

    def ask(
        self,
        node: str,
        now_s: float,
        progress_ns: int,
        list_client: C,
        get_client: C,
    ) -> None:
        """Start asking ``node`` (at monotonic ``now_s``, the recorder at ``progress_ns``)."""
        self.pending.append(PendingSnapshot(node, now_s, progress_ns, list_client, get_client))

    def step(self, now_s: float) -> SnapshotRound[C]:
        """One step of asking every pending node at monotonic ``now_s`` (s); the answered and
        ended ones leave."""
        out: SnapshotRound[C] = SnapshotRound()
        for snap in list(self.pending):
            done, answer = self._advance(snap, now_s)
            if answer is not None:
                out.answered.append(answer)
            if done:
                self.pending.remove(snap)
                out.ended.append(snap)
        return out

    def overdue(self, now_s: float) -> list[PendingSnapshot[C]]:
        """The pending nodes that just passed the timeout (each reported once)."""
        late = [s for s in self.pending if now_s - s.started_s > self.timeout_s and not s.warned]
        for snap in late:
            snap.warned = True
        return late

    def held_ns(self, progress_ns: int) -> int:
        """``progress_ns``, held where a node appeared while it has not answered or timed out."""
        return min([progress_ns, *(s.progress_ns for s in self.pending if not s.warned)])

    def _advance(
        self, snap: PendingSnapshot[C], now_s: float
    ) -> tuple[bool, ParameterSnapshot | None]:
        """(done, its parameters if they came) after one step of asking ``snap``."""
        client = snap.list_client if snap.names is None else snap.get_client
        answered = next((f for f in snap.futures if f.done()), None)
        if answered is None:
            if snap.futures and now_s - snap.asked_s <= self.timeout_s:
                return False, None
            # not asked yet, or no answer within the timeout (the response may be lost): ask
            # (again), keeping the earlier requests, whose answer may still come
            if len(snap.futures) == MAX_ASKED:
                client.remove_pending_request(snap.futures.pop(0))
            if client.service_is_ready():
                request = (
                    self._list_request() if snap.names is None else self._get_request(snap.names)
                )
                snap.futures.append(client.call_async(request))
                snap.asked_s = now_s
            return False, None
        for other in snap.futures:
            if other is not answered:
                client.remove_pending_request(other)
        snap.futures = []
        result = answered.result()
        if result is None:
            return True, None
        if snap.names is not None:
            return True, ParameterSnapshot(snap.node, snap.names, list(result.values))
        snap.names = list(result.result.names)
        return self._advance(snap, now_s)  # ask for the values at once
