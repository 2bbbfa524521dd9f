"""Parameter snapshots: which nodes the recorder asks for their parameters, and how far each is.

Every node of the recorder's namespaces (its own, or those it is given: a teleoperation graph's
``/master`` and ``/slave``; not hidden ones nor the recorder) is asked once,
when it appears: ``list_parameters``, then ``get_parameters`` of every name. A node silent for
the timeout is reported once and still asked: the question is sent again every timeout (a loaded
node answers late, and rmw_fastrtps drops a response when the node has not yet matched the
asking client's response reader 100 ms after answering, which happens right after discovery on a
loaded machine; a client dropped under a pending request makes the node's own executor fail to
send its response, so the recorder keeps its clients until the node answered). Until a node
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
    future: Any = None  # of the question asked
    asked_s: float = 0.0  # when it was asked (monotonic, s)
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
        if snap.future is not None and not snap.future.done():
            if now_s - snap.asked_s <= self.timeout_s:
                return False, None
            # no answer within the timeout: the response may be lost, ask again
            client = snap.list_client if snap.names is None else snap.get_client
            client.remove_pending_request(snap.future)
            snap.future = None
        if snap.future is not None:
            result, snap.future = snap.future.result(), None
            if result is None:
                return True, None
            if snap.names is not None:
                return True, ParameterSnapshot(snap.node, snap.names, list(result.values))
            snap.names = list(result.result.names)
        if snap.names is None:
            if snap.list_client.service_is_ready():
                snap.future = snap.list_client.call_async(self._list_request())
        elif snap.get_client.service_is_ready():
            snap.future = snap.get_client.call_async(self._get_request(snap.names))
        if snap.future is not None:
            snap.asked_s = now_s
        return False, None
