"""Parameter snapshots: which nodes are asked, the list-then-get steps, timeouts, the hold."""

from __future__ import annotations

from dataclasses import dataclass, field
from types import SimpleNamespace
from typing import Any

from haptic_dob.recorder.snapshots import MAX_ASKED, ParameterSnapshot, SnapshotTracker


@dataclass
class Future:
    """A reply that comes when the test says so."""

    value: Any = None
    ready: bool = False

    def done(self) -> bool:
        return self.ready

    def result(self) -> Any:
        return self.value


@dataclass
class Client:
    """A service client whose service appears when the test says so; keeps its requests."""

    ready: bool = True
    requests: list[Any] = field(default_factory=list)
    futures: list[Future] = field(default_factory=list)
    removed: list[Future] = field(default_factory=list)

    def service_is_ready(self) -> bool:
        return self.ready

    def call_async(self, request: Any) -> Future:
        self.requests.append(request)
        self.futures.append(Future())
        return self.futures[-1]

    def remove_pending_request(self, future: Future) -> None:
        self.removed.append(future)


def tracker(timeout_s: float = 2.0) -> SnapshotTracker[Client]:
    return SnapshotTracker(
        "/ns/recorder_node",
        "/ns",
        timeout_s,
        lambda: ("list", 0),
        lambda names: ("get", tuple(names)),
    )


def test_new_nodes_of_the_namespace_are_asked_once() -> None:
    t = tracker()
    graph = [
        ("recorder_node", "/ns"),  # itself
        ("device_node", "/ns"),
        ("_hidden", "/ns"),
        ("other_node", "/elsewhere"),
        ("controller_node", "/ns"),
    ]
    assert t.appeared(graph) == ["/ns/device_node", "/ns/controller_node"]
    assert t.appeared([*graph, ("observer_node", "/ns")]) == ["/ns/observer_node"]
    root = SnapshotTracker[Client]("/recorder_node", "/", 2.0, list, list)
    assert root.appeared([("device_node", "/"), ("recorder_node", "/")]) == ["/device_node"]


def test_parameters_are_listed_then_got() -> None:
    t = tracker()
    lister, getter = Client(ready=False), Client()
    t.ask("/ns/device_node", 10.0, 5, lister, getter)
    assert t.step(10.0).answered == [] and lister.requests == []  # no service yet
    lister.ready = True
    t.step(10.5)
    assert lister.requests == [("list", 0)]
    t.step(12.5)  # no answer yet, within the timeout: nothing asked again
    assert len(lister.requests) == 1 and getter.requests == []
    lister.futures[0].value = SimpleNamespace(result=SimpleNamespace(names=["a", "b"]))
    lister.futures[0].ready = True
    assert t.step(12.6).answered == []
    assert getter.requests == [("get", ("a", "b"))]
    getter.futures[0].value = SimpleNamespace(values=("va", "vb"))
    getter.futures[0].ready = True
    done = t.step(12.7)
    assert done.answered == [ParameterSnapshot("/ns/device_node", ["a", "b"], ["va", "vb"])]
    assert [s.node for s in done.ended] == ["/ns/device_node"]
    assert done.ended[0].list_client is lister and done.ended[0].get_client is getter
    assert t.pending == []


def test_a_failed_call_ends_without_a_snapshot() -> None:
    t = tracker()
    lister = Client()
    t.ask("/ns/device_node", 10.0, 5, lister, Client())
    t.step(10.0)
    lister.futures[0].ready = True  # result None: the call failed
    done = t.step(10.1)
    assert done.answered == [] and [s.node for s in done.ended] == ["/ns/device_node"]


def test_a_question_without_an_answer_is_asked_again_every_timeout() -> None:
    """A lost response (rmw_fastrtps drops it when the node has not matched the client's response
    reader yet) does not leave the node unasked: each question goes again after the timeout; the
    earlier requests wait on, the first answer counts and the others are dropped."""
    t = tracker(timeout_s=2.0)
    lister, getter = Client(), Client()
    t.ask("/ns/device_node", 10.0, 5, lister, getter)
    t.step(10.0)
    t.step(12.0)  # exactly the timeout: not yet
    assert len(lister.requests) == 1
    t.step(12.1)
    assert lister.requests == [("list", 0)] * 2 and lister.removed == []
    t.step(14.0)  # the timeout counts from the question asked again
    assert len(lister.requests) == 2
    # the first request answers late: it counts, the second is dropped, the values are asked
    lister.futures[0].value = SimpleNamespace(result=SimpleNamespace(names=["a"]))
    lister.futures[0].ready = True
    t.step(14.2)
    assert lister.removed == [lister.futures[1]]
    assert getter.requests == [("get", ("a",))]
    t.step(16.3)  # the get is asked again too
    assert getter.requests == [("get", ("a",))] * 2
    getter.futures[1].value = SimpleNamespace(values=("va",))
    getter.futures[1].ready = True
    done = t.step(16.4)
    assert done.answered == [ParameterSnapshot("/ns/device_node", ["a"], ["va"])]
    assert getter.removed == [getter.futures[0]] and t.pending == []


def test_at_most_max_asked_requests_of_a_question_wait_at_once() -> None:
    t = tracker(timeout_s=1.0)
    lister = Client()
    t.ask("/ns/device_node", 0.0, 5, lister, Client())
    for k in range(MAX_ASKED + 2):
        t.step(1.5 * k)
    assert len(lister.requests) == MAX_ASKED + 2
    assert lister.removed == lister.futures[:2]  # the oldest dropped for each new one


def test_progress_is_held_until_answered_or_timed_out() -> None:
    t = tracker(timeout_s=2.0)
    assert t.held_ns(700) == 700  # nobody asked
    t.ask("/ns/a", 10.0, 300, Client(ready=False), Client())
    t.ask("/ns/b", 11.0, 500, Client(ready=False), Client())
    assert t.held_ns(700) == 300
    assert t.held_ns(200) == 200  # never ahead of the progress itself
    assert t.overdue(12.0) == []  # exactly the timeout: not yet
    assert [s.node for s in t.overdue(12.5)] == ["/ns/a"]
    assert t.overdue(12.6) == []  # reported once
    assert t.held_ns(700) == 500  # a is still asked, but no longer holds the progress
    assert [s.node for s in t.overdue(13.1)] == ["/ns/b"]
    assert t.held_ns(700) == 700
    assert [s.node for s in t.pending] == ["/ns/a", "/ns/b"]  # still asked
