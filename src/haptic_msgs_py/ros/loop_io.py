"""Publishers and subscriptions of the loop's topics: in process first, DDS for everyone else.

``LoopPublisher.publish(value)`` hands the value to the subscribers in this process at once
(``haptic_msgs_py.bus``) and sends it on DDS after the command. In a composed process a topic
goes on DDS only while a reader elsewhere is matched (the count follows the publisher's matched
events; a lockstep device waits before sample 0 until every publisher of its process matched the
readers the graph shows); a node alone in its process sends always, but ``on_demand`` topics
(evaluation only) only while a reader is matched. ``LoopSubscription`` takes values from
publishers in this process and opens a DDS subscription only while the topic has none here
(``listen_outside``: values from DDS too, to a callback of their own). Every node keeps its
ordinary rclpy publishers, so ``ros2 topic list``/``info``/``echo`` see the same graph whether
nodes share a process or not. Why: docs/design/timing.md.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from rclpy.event_handler import PublisherEventCallbacks, QoSPublisherMatchedInfo
from rclpy.node import Node
from rclpy.qos import QoSProfile

from haptic_msgs_py.bus import Bus, bus_for
from haptic_msgs_py.codecs import Codec
from haptic_msgs_py.ros.raw import rclpy_type


class LoopPublisher:
    """One loop topic's publisher (values of ``codec``; messages carry ``frame_id``)."""

    def __init__(
        self,
        node: Node,
        topic: str,
        codec: Codec,
        qos: QoSProfile,
        frame_id: str = "",
        on_demand: bool = False,
    ) -> None:
        self.topic = node.resolve_topic_name(topic)
        self.on_demand = on_demand
        self.readers = 0  # DDS readers matched (in other processes, or plain rclpy ones here)
        self.pub = node.create_publisher(
            rclpy_type(codec.typename),
            topic,
            qos,
            event_callbacks=PublisherEventCallbacks(matched=self._on_matched),
        )
        self.readers = self.pub.get_subscription_count()
        self._encode = codec.encoder(frame_id)
        self._send_bytes = self.pub.publish
        self.bus: Bus = bus_for(node.context)
        self.bus.join(node.get_fully_qualified_name())
        self._local = self.bus.add_publisher(self.topic, self).subscribers
        self._active = False

    def _on_matched(self, info: QoSPublisherMatchedInfo) -> None:
        self.readers = info.current_count

    @property
    def wanted(self) -> bool:
        """A publish would reach someone (or goes on DDS whatever, see the module's notes)."""
        return bool(self._local) or self.readers > 0 or not (self.on_demand or self.bus.composed)

    def publish(self, value: Any) -> None:
        """Hand ``value`` over in process now; send it on DDS after the outermost publish."""
        bus = self.bus
        if self._active:  # published again from inside its own delivery: after this one
            bus.soon.append(lambda: self.publish(value))
            return
        local = self._local
        if self.readers or not (self.on_demand or bus.composed):
            bus.outbox.append((self.send, value))
        if local:
            self._active = True
            try:
                bus.deliver(local, value)
            finally:
                self._active = False
        elif not bus.depth and bus.outbox:
            bus.flush()

    def send(self, value: Any) -> None:
        """Encode and send ``value`` on DDS now."""
        self._send_bytes(self._encode(value))

    def get_subscription_count(self) -> int:
        """DDS readers matched now (asks the middleware)."""
        return self.pub.get_subscription_count()

    def destroy(self, node: Node) -> None:
        """Leave the bus and destroy the DDS publisher."""
        self.bus.remove_publisher(self.topic, self)
        node.destroy_publisher(self.pub)


class LoopSubscription:
    """One loop topic's input: ``callback(value)`` from publishers here, or from DDS
    (``outside(value)`` when given). A controller's inputs are ``first``: publishers here call
    them before the topic's other subscribers (``Bus.add_subscriber``)."""

    def __init__(
        self,
        node: Node,
        topic: str,
        codec: Codec,
        callback: Callable[[Any], None],
        qos: QoSProfile,
        outside: Callable[[Any], None] | None = None,
        first: bool = False,
    ) -> None:
        self.node = node
        self.topic = node.resolve_topic_name(topic)
        self._name = topic
        self._callback = outside or callback
        self._decode = codec.decoder()
        self._type = rclpy_type(codec.typename)
        self._qos = qos
        self.dds: Any = None
        self.outside = False  # listen on DDS while a publisher is here, too
        self.bus = bus_for(node.context)
        self.bus.join(node.get_fully_qualified_name())
        self._topic = self.bus.add_subscriber(self.topic, callback, self._follow, first)
        self._follow()

    @property
    def local(self) -> int:
        """Publishers of the topic in this process."""
        return len(self._topic.publishers)

    def listen_outside(self, on: bool) -> None:
        """Listen on DDS also while a publisher of the topic is in this process (``on``), or
        only while none is (the default)."""
        self.outside = on
        self._follow()

    def _follow(self) -> None:
        """Listen on DDS while no publisher of the topic is in this process (or ``outside``)."""
        listen = self.outside or not self._topic.publishers
        if listen and self.dds is None:
            self.dds = self.node.create_subscription(
                self._type, self._name, self._on_bytes, self._qos, raw=True
            )
        elif not listen and self.dds is not None:
            self.node.destroy_subscription(self.dds)
            self.dds = None

    def _on_bytes(self, data: bytes) -> None:
        self._callback(self._decode(data))

    def get_publisher_count(self) -> int:
        """Publishers here and, while listening on DDS, the matched ones elsewhere."""
        return len(self._topic.publishers) + (self.dds.get_publisher_count() if self.dds else 0)
