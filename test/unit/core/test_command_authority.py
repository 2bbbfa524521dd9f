"""The command authority: which effort commands from other processes move the device, what is
counted, and what is said once per publisher (the graph a fake, the clock a counter)."""

from __future__ import annotations

from collections.abc import Sequence

import pytest

from haptic_dob.core.command_authority import (
    LOOK_AGAIN_S,
    NAME_GRACE_S,
    CommandAuthority,
    Endpoint,
    Verdict,
    new_token,
)

SOURCE = "/ns/controller_node"
CTL = Endpoint(SOURCE, "01.aa")
STRAY = Endpoint("/ns/stray", "02.bb")


class FakeGraph:
    """The middleware's view: the publishers outside the process, how many the input matched;
    counts the looks."""

    def __init__(self, *endpoints: Endpoint) -> None:
        self.endpoints = list(endpoints)
        self.hidden = 0  # publishers matched that the graph does not list yet
        self.looks = 0

    def matched(self) -> int:
        return len(self.endpoints) + self.hidden

    def publishers(self) -> Sequence[Endpoint]:
        self.looks += 1
        return list(self.endpoints)

    def unlisted(self) -> int:
        return self.hidden


class Clock:
    def __init__(self) -> None:
        self.t = 100.0

    def __call__(self) -> float:
        return self.t


def authority(
    graph: FakeGraph, token: str = "", open_input: bool = False
) -> tuple[CommandAuthority, list[str], list[str], Clock]:
    warned: list[str] = []
    told: list[str] = []
    clock = Clock()
    a = CommandAuthority(SOURCE, graph, token, open_input, warned.append, told.append, clock)
    return a, warned, told, clock


def test_tokens_are_fresh_and_hex() -> None:
    tokens = {new_token() for _ in range(50)}
    assert len(tokens) == 50 and all(len(t) == 16 and int(t, 16) >= 0 for t in tokens)


def test_with_a_session_token_only_commands_carrying_it_move_the_device() -> None:
    graph = FakeGraph(CTL, STRAY)
    a, warned, _, _ = authority(graph, token="s3cret")
    assert a.admit("s3cret") is Verdict.TAKE
    assert graph.looks == 0  # the loop's own commands cost a comparison, never a graph look
    for token in ("", "guess", "s3cret2"):
        assert a.admit(token) is Verdict.REFUSE
    assert a.refused == 3 and a.taken == 0
    assert len(warned) == 1 and "/ns/stray (GID 02.bb)" in warned[0]  # named once
    assert a.named == {"02.bb": "/ns/stray"}
    assert a.admit("s3cret") is Verdict.TAKE  # the loop's controller is never refused


def test_the_middlewares_copy_of_a_command_taken_in_process_is_dropped_uncounted() -> None:
    a, warned, _, _ = authority(FakeGraph(STRAY), token="s3cret")
    assert a.admit("s3cret", here="s3cret") is Verdict.COPY
    assert a.admit("random1", here="random1") is Verdict.COPY  # a composed controller's own token
    assert a.admit("", here="") is Verdict.REFUSE  # no token is never a copy
    assert a.refused == 1 and len(warned) == 1


def test_open_input_takes_every_command_and_names_each_publisher_once() -> None:
    a, warned, told, _ = authority(FakeGraph(CTL, STRAY), token="s3cret", open_input=True)
    assert [a.admit(t) for t in ("", "x", "s3cret")] == [Verdict.TAKE] * 3
    assert a.taken == 2 and a.refused == 0 and warned == []
    assert len(told) == 1 and "/ns/stray" in told[0] and "open_command_input" in a.mode


def test_without_a_token_the_sources_is_taken_while_the_graph_shows_it_alone() -> None:
    graph = FakeGraph(CTL)
    a, warned, told, _ = authority(graph)
    assert "waiting" in a.mode
    assert a.admit("ctl1") is Verdict.TAKE  # learnt: the graph shows the source alone
    assert a.expected == "ctl1" and len(told) == 1 and "01.aa" in told[0]
    graph.endpoints.append(STRAY)
    assert a.admit("stray1") is Verdict.REFUSE  # another token from another publisher
    assert a.admit("") is Verdict.REFUSE
    assert a.admit("ctl1") is Verdict.TAKE  # the loop's own, while the stray is there
    assert a.refused == 2 and len(warned) == 1


def test_without_a_token_nothing_is_learnt_while_another_publisher_is_there() -> None:
    a, _, _, _ = authority(FakeGraph(CTL, STRAY))
    assert a.admit("ctl1") is Verdict.REFUSE  # which of the two sent it? fail closed
    assert a.expected == "" and a.refused == 1


def test_without_a_token_the_same_source_cannot_change_its_token() -> None:
    graph = FakeGraph(CTL)
    a, _, _, clock = authority(graph)
    assert a.admit("ctl1") is Verdict.TAKE
    clock.t += 2 * LOOK_AGAIN_S
    assert a.admit("other") is Verdict.REFUSE  # same GID, another token: someone else's
    graph.endpoints = [Endpoint(SOURCE, "01.cc")]  # the controller restarted: a new GID
    clock.t += 2 * LOOK_AGAIN_S
    assert a.admit("ctl2") is Verdict.TAKE and a.expected == "ctl2"


def test_the_graph_is_looked_at_again_when_the_matched_publishers_change_or_it_is_old() -> None:
    graph = FakeGraph(CTL, STRAY)
    a, _, _, clock = authority(graph, token="s3cret")
    a.admit("")
    a.admit("")
    assert graph.looks == 1  # a flood of refusals looks once
    graph.endpoints.append(Endpoint("/ns/another", "03.cc"))
    a.admit("")
    assert graph.looks == 2
    clock.t += LOOK_AGAIN_S
    a.admit("")
    assert graph.looks == 3


def test_a_publisher_the_graph_knows_by_gid_alone_is_named_once_it_knows_it() -> None:
    graph = FakeGraph(CTL, Endpoint("", "02.bb"))
    a, warned, _, _ = authority(graph, token="s3cret")
    assert a.admit("") is Verdict.REFUSE
    assert warned == [] and a.named == {}  # its node is not discovered yet: wait
    graph.endpoints[1] = STRAY
    a.follow_up()
    assert len(warned) == 1 and "/ns/stray (GID 02.bb)" in warned[0]
    a.follow_up()
    a.admit("")
    assert len(warned) == 1


@pytest.mark.parametrize("leaves", [False, True])
def test_a_publisher_never_named_by_the_graph_is_named_by_its_gid(leaves: bool) -> None:
    graph = FakeGraph(CTL, Endpoint("", "02.bb"))
    a, warned, _, clock = authority(graph, token="s3cret")
    a.admit("")
    if leaves:
        graph.endpoints.pop()
    else:
        clock.t += NAME_GRACE_S
    a.follow_up()
    assert len(warned) == 1 and "(GID 02.bb)" in warned[0]


def test_a_refusal_nobody_in_the_graph_can_be_named_for_is_said_once() -> None:
    graph = FakeGraph(CTL)  # the stray left, or uses the source's name
    a, warned, _, _ = authority(graph, token="s3cret")
    a.admit("")
    a.admit("x")
    assert a.refused == 2 and len(warned) == 1 and "01.aa" in warned[0]


@pytest.mark.parametrize("beside", [(), (STRAY,)])
def test_a_publisher_matched_before_the_graph_lists_it_is_named_once_it_is_listed(
    beside: tuple[Endpoint, ...],
) -> None:
    """A stray's commands arrive (the input matched it) before the graph lists it, beside
    another stray already named or none: it is named when the graph lists it, not before, and
    nothing generic is said."""
    graph = FakeGraph(CTL, *beside)
    graph.hidden = 1
    a, warned, _, clock = authority(graph, token="s3cret")
    a.admit("")
    a.admit("")
    assert len(warned) == len(beside)  # only the one listed
    clock.t += 0.5
    a.follow_up()  # still unlisted: wait
    assert len(warned) == len(beside)
    graph.hidden, late = 0, Endpoint("/ns/late", "04.dd")
    graph.endpoints.append(late)
    a.follow_up()
    assert len(warned) == len(beside) + 1 and "/ns/late (GID 04.dd)" in warned[-1]
    a.follow_up()
    a.admit("")
    assert len(warned) == len(beside) + 1 and a.refused == 3


@pytest.mark.parametrize("leaves", [False, True])
def test_a_publisher_that_the_graph_never_lists_is_said_once_as_unnamed(leaves: bool) -> None:
    """Gone before the graph listed it (the matched count falls back), or still unlisted after
    the grace: one line says a refused publisher cannot be named."""
    graph = FakeGraph(CTL, STRAY)
    graph.hidden = 1
    a, warned, _, clock = authority(graph, token="s3cret")
    a.admit("")
    assert len(warned) == 1  # the stray listed
    if leaves:
        graph.hidden = 0
    else:
        clock.t += NAME_GRACE_S
    a.follow_up()
    assert len(warned) == 2 and "does not tell apart by name" in warned[-1]
    a.follow_up()
    assert len(warned) == 2


def test_a_source_matched_before_the_graph_lists_it_says_nothing_generic() -> None:
    """The loop's controller restarts while a named stray goes on: its new endpoint is matched
    before the graph lists it, and a refusal of the stray's comes meanwhile. Once the graph
    lists the controller, nothing is left unnamed: no generic line."""
    graph = FakeGraph(CTL, STRAY)
    a, warned, _, clock = authority(graph, token="s3cret")
    a.admit("")
    assert len(warned) == 1
    graph.endpoints.remove(CTL)
    graph.hidden = 1  # the restarted controller, matched, not listed yet
    clock.t += LOOK_AGAIN_S
    a.admit("")
    graph.hidden = 0
    graph.endpoints.append(Endpoint(SOURCE, "01.cc"))
    a.follow_up()
    clock.t += NAME_GRACE_S
    a.follow_up()
    assert len(warned) == 1 and a.refused == 2
