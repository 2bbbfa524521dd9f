"""The in-process bus: depth-first hand-over, sends after the outermost publish, deferred work."""

from __future__ import annotations

from typing import Any

from haptic_msgs_py.bus import Bus, bus_for


class Pub:
    """A minimal publisher on a bus: local subscribers at once, a 'send' queued for later."""

    def __init__(self, bus: Bus, name: str, log: list[str], readers: bool = True) -> None:
        self.bus, self.name, self.log, self.readers = bus, name, log, readers
        self.local = bus.add_publisher(name, self).subscribers

    def send(self, value: Any) -> None:
        self.log.append(f"send {self.name} {value}")

    def publish(self, value: Any) -> None:
        if self.readers:
            self.bus.send_later(self.send, value)
        self.bus.deliver(self.local, value)


def test_a_chain_runs_depth_first_and_sends_go_out_after_the_outermost_publish() -> None:
    bus, log = Bus(), []
    sample, wall, command = (Pub(bus, n, log) for n in ("/sample", "/wall", "/command"))

    def environment(k: int) -> None:
        log.append(f"env {k}")
        wall.publish(k)

    def controller(k: int) -> None:
        log.append(f"ctl {k}")
        command.publish(k)

    bus.add_subscriber("/sample", environment, lambda: None)
    bus.add_subscriber("/wall", controller, lambda: None)
    bus.add_subscriber("/command", lambda k: log.append(f"device {k}"), lambda: None)
    sample.publish(7)
    assert log == [
        "env 7",
        "ctl 7",
        "device 7",  # the command reached the device before anything was sent
        "send /sample 7",
        "send /wall 7",
        "send /command 7",
    ]


def test_a_batch_holds_the_sends_until_it_ends() -> None:
    bus, log = Bus(), []
    a, b = Pub(bus, "/a", log), Pub(bus, "/b", log)
    bus.add_subscriber("/b", lambda v: log.append(f"got {v}"), lambda: None)
    with bus.batch():
        a.publish(1)
        b.publish(2)
        assert log == ["got 2"]
    assert log == ["got 2", "send /a 1", "send /b 2"]


def test_a_controllers_input_is_heard_first_whenever_it_joined() -> None:
    """A ``first`` subscriber (a controller's) is called before the others on its topic, in the
    order the first ones joined, even when an observer joined before it."""
    bus, log = Bus(), []
    pub = Pub(bus, "/joint_states", log, readers=False)
    bus.add_subscriber("/joint_states", lambda v: log.append(f"observer {v}"), lambda: None)
    bus.add_subscriber("/joint_states", lambda v: log.append(f"controller {v}"), lambda: None, True)
    bus.add_subscriber("/joint_states", lambda v: log.append(f"recorder {v}"), lambda: None)
    bus.add_subscriber("/joint_states", lambda v: log.append(f"second {v}"), lambda: None, True)
    pub.publish(3)
    assert log == ["controller 3", "second 3", "observer 3", "recorder 3"]


def test_work_given_during_a_publish_runs_after_it_and_at_once_outside() -> None:
    bus, log = Bus(), []
    pub = Pub(bus, "/x", log, readers=False)
    bus.add_subscriber(
        "/x", lambda v: bus.call_soon(lambda: log.append(f"later {v}")), lambda: None
    )
    pub.publish(1)
    assert log == [] and len(bus.soon) == 1
    bus.run_soon()
    assert log == ["later 1"] and not bus.soon
    bus.call_soon(lambda: log.append("now"))
    assert log == ["later 1", "now"]


def test_run_soon_runs_work_that_defers_more_work_until_its_budget() -> None:
    bus = Bus()
    count = [0]

    def step() -> None:  # a lockstep device: each step defers the next
        count[0] += 1
        bus.depth += 1
        bus.call_soon(step)
        bus.depth -= 1

    bus.call_soon(step)
    bus.run_soon(budget_s=0.01)
    assert count[0] > 10 and len(bus.soon) == 1  # stopped at its budget, the next step waits


def test_subscribers_hear_when_a_publisher_of_their_topic_comes_and_goes() -> None:
    bus, heard = Bus(), []
    topic = bus.add_subscriber("/t", lambda v: None, lambda: heard.append(len(topic.publishers)))
    pub = object()
    bus.add_publisher("/t", pub)
    bus.remove_publisher("/t", pub)
    assert heard == [1, 0]
    assert bus.publishers() == []


def test_one_bus_per_context_and_composition_is_known() -> None:
    ctx_a, ctx_b = object.__new__(type("Ctx", (), {})), object.__new__(type("Ctx", (), {}))
    assert bus_for(ctx_a) is bus_for(ctx_a) and bus_for(ctx_a) is not bus_for(ctx_b)
    bus = bus_for(ctx_a)
    bus.join("/device_node")
    assert not bus.composed
    bus.join("/device_node")
    assert not bus.composed
    bus.join("/controller_node")
    assert bus.composed
