"""A topic's publishers as the recorder hears of them: a match lost mid-stream and found again
is said once it comes back; a session's end says nothing; middleware losses are said."""

from __future__ import annotations

from haptic_dob.recorder.publishers import PublisherWatch


def test_a_match_lost_mid_stream_is_said_when_it_comes_back() -> None:
    w = PublisherWatch("/joint_states")
    assert w.on_matched(1, 0.0, received=0) is None  # the start: nothing to say
    assert w.on_matched(0, 20.5, received=20_000) is None  # gone: maybe the session's end
    line = w.on_matched(1, 57.75, received=20_000)
    assert line == (
        "/joint_states: publisher(s) matched again after 37.2 s without any (what they sent "
        "meanwhile did not reach the recorder)"
    )
    assert (w.rematches, w.lost_at_s, w.matched) == (1, None, 1)
    assert w.on_matched(2, 58.0, received=20_001) is None  # a second one: no loss between


def test_no_line_at_the_end_nor_for_a_publisher_that_never_sent() -> None:
    w = PublisherWatch("/ee_pose")
    w.on_matched(1, 0.0, received=0)
    assert w.on_matched(0, 1.0, received=0) is None  # left before sending: not a loss
    assert w.on_matched(1, 2.0, received=0) is None
    assert w.on_matched(0, 9.0, received=500) is None  # the session ended
    assert w.rematches == 0 and w.lost_at_s == 9.0


def test_one_of_two_publishers_leaving_is_not_a_loss() -> None:
    w = PublisherWatch("/parameter_events")
    w.on_matched(2, 0.0, received=3)
    assert w.on_matched(1, 1.0, received=9) is None
    assert w.on_matched(2, 2.0, received=9) is None
    assert w.rematches == 0


def test_samples_the_middleware_lost_are_said() -> None:
    w = PublisherWatch("/effort_command")
    assert w.on_lost(0, 0) is None
    assert w.on_lost(3, 3) == "/effort_command: the middleware reports 3 sample(s) lost (3 in all)"
    assert w.on_lost(5, 2) == "/effort_command: the middleware reports 2 sample(s) lost (5 in all)"
    assert w.lost_messages == 5
