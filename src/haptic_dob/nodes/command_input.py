"""A device end's ``effort_command`` input under the command authority: what the simulated device
node and the device bridge take their commands through.

Commands handed over in this process (the loop composed) reach the device at once. Commands from
other processes pass ``haptic_dob.core.command_authority`` first, which asks the middleware here
about the topic's publishers (node name, endpoint GID). A device with the topic's publisher in its
process listens on DDS only while the graph shows a publisher of the topic outside it (looked at
every ``LOOK_EVERY_S``): a stray publisher's commands are refused, counted and named there too,
and while there is none this costs the loop nothing. While there is one, the loop's own
controller sends its commands on DDS as well (a reader is matched) and the device drops those
copies. Parameters: ``haptic_dob.nodes.settings.CommandInputSettings``.
"""

from __future__ import annotations

from collections.abc import Callable, Mapping
from typing import Any

from rclpy.qos import QoSProfile

from haptic_dob.core.command_authority import CommandAuthority, Endpoint, Verdict
from haptic_dob.runtime.ros.spin import LoopNode
from haptic_msgs_py import codecs
from haptic_msgs_py.ros.loop_io import LoopSubscription
from haptic_msgs_py.topics import EFFORT_COMMAND
from haptic_msgs_py.values import EffortCommand

LOOK_EVERY_S = 0.25  # a composed device looks this often for publishers outside its process


def qualified(name: str, namespace: str) -> str:
    """``name`` as a fully qualified node name (a name starting with ``/`` already is one)."""
    if name.startswith("/"):
        return name
    return f"{namespace.rstrip('/')}/{name}"


#: what rclpy names a node the graph does not know yet (its endpoint was discovered first)
UNKNOWN = ("_NODE_NAME_UNKNOWN_", "_NODE_NAMESPACE_UNKNOWN_")


def gid_text(gid: Any) -> str:
    """An endpoint GID as ``ros2 topic info --verbose`` prints it (``01.0f.7f...``)."""
    return ".".join(f"{int(b):02x}" for b in gid)


class CommandInput:
    """The device end's ``effort_command``: ``take(command)`` for every command that may move
    the device.

    Args:
        node: the device end's node.
        take: where commands that move the device go.
        qos: the input's QoS.
        values: the node's parameter values (``CommandInputSettings``).
    """

    def __init__(
        self,
        node: LoopNode,
        take: Callable[[EffortCommand], None],
        qos: QoSProfile,
        values: Mapping[str, Any],
    ) -> None:
        self.node = node
        self._take = take
        self._here = ""  # the token of the commands handed over in this process
        self._said_refused = 0
        self._listed = 0  # the topic's publishers the graph listed at the last look
        self.authority = CommandAuthority(
            qualified(values["command_source"], node.get_namespace()),
            self,
            values["command_token"],
            values["open_command_input"],
            warn=node.log.warning,
            info=node.log.info,
        )
        self.sub = LoopSubscription(
            node, EFFORT_COMMAND, codecs.EFFORT, self._from_here, qos, outside=self._from_elsewhere
        )
        self.bus = self.sub.bus
        node.create_timer(LOOK_EVERY_S, self._look_outside)

    def _from_here(self, cmd: EffortCommand) -> None:
        self._here = cmd.token
        self._take(cmd)

    def _from_elsewhere(self, cmd: EffortCommand) -> None:
        here = self._here if self.sub.local else ""
        if self.authority.admit(cmd.token, here) is Verdict.TAKE:
            self._take(cmd)

    def _look_outside(self) -> None:
        """With the topic's publisher here: listen on DDS while one is outside, too; name the
        publishers refused before the graph knew their node."""
        self.authority.follow_up()
        local = self.sub.local
        outside = local > 0 and self.node.count_publishers(self.sub.topic) > local
        if outside != self.sub.outside:
            self.sub.listen_outside(outside)

    # --- Graph: the middleware's view of the topic ----------------------------------------
    def matched(self) -> int:
        """Publishers the DDS input has matched now."""
        dds = self.sub.dds
        return int(dds.get_publisher_count()) if dds is not None else 0

    def publishers(self) -> list[Endpoint]:
        """The topic's publishers outside this process (by node name), as the graph shows them."""
        here = self.bus.nodes
        out = []
        infos = self.node.get_publishers_info_by_topic(self.sub.topic)
        self._listed = len(infos)
        for info in infos:
            if (info.node_name, info.node_namespace) == UNKNOWN:
                name = ""
            else:
                name = qualified(info.node_name, info.node_namespace)
            if name not in here:
                out.append(Endpoint(name, gid_text(info.endpoint_gid)))
        return out

    def unlisted(self) -> int:
        """Publishers the DDS input has matched beyond those the last ``publishers()`` listed
        (here and elsewhere)."""
        return max(0, self.matched() - self._listed)

    # --- what the node reports --------------------------------------------------------------
    def get_publisher_count(self) -> int:
        """Publishers here and, while listening on DDS, the matched ones elsewhere."""
        return self.sub.get_publisher_count()

    def refusing(self) -> bool:
        """Commands were refused since the last call."""
        refused = self.authority.refused
        news = refused > self._said_refused
        self._said_refused = refused
        return news

    def report(self) -> dict[str, Any]:
        """The ``/diagnostics`` values of the command authority."""
        a = self.authority
        values: dict[str, Any] = {
            "command_authority": a.mode,
            "foreign_commands_refused": a.refused,
        }
        if a.open_input:
            values["foreign_commands_taken"] = a.taken
        if a.named:
            values["foreign_publishers"] = ", ".join(f"{n} (GID {g})" for g, n in a.named.items())
        return values
