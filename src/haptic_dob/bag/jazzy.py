"""The ``rosbags`` writer as rosbag2 Jazzy writes a bag: ``ros_distro: jazzy``, the offered QoS.

``rosbags`` writes the version-9 format of rosbag2 Jazzy (``metadata.yaml``, the MCAP ``ros2``
profile, the sqlite3 schema 4), offered QoS profiles included (``add_connection``'s
``offered_qos_profiles``: ``metadata.yaml`` a sequence of maps with the policies' names, as
rosbag2_storage's ``qos.cpp`` encodes version 9; MCAP channels and sqlite3 topics the same as YAML
text), but it names ``rosbags`` as the ROS distribution. ``JazzyWriter`` names ``jazzy`` in the
three places rosbag2 does. ``offered_qos`` turns a QoS profile as the ROS graph reports a
publisher's (``get_publishers_info_by_topic``) into the ``rosbags`` one, field for field, as
``ros2 bag record`` stores it; ``ros2 bag play`` offers it again (docs/recording-and-analysis.md).
"""

from __future__ import annotations

import re
from typing import Protocol, TypeVar

from rosbags.interfaces import (
    Qos,
    QosDurability,
    QosHistory,
    QosLiveliness,
    QosReliability,
    QosTime,
)
from rosbags.rosbag2 import Writer

from haptic_msgs_py.stamps import NS_PER_S

ROS_DISTRO = "jazzy"  # the distribution whose rosbag2 reads these bags
_DISTRO = re.compile(r"^(\s*ros_distro: )rosbags$", re.MULTILINE)
_Policy = TypeVar("_Policy", QosHistory, QosReliability, QosDurability, QosLiveliness)


class Duration(Protocol):
    """A duration with its nanoseconds (``rclpy.duration.Duration``)."""

    @property
    def nanoseconds(self) -> int: ...


class EndpointQos(Protocol):
    """A QoS profile as the graph reports a publisher's (``rclpy.qos.QoSProfile``)."""

    @property
    def history(self) -> int: ...
    @property
    def depth(self) -> int: ...
    @property
    def reliability(self) -> int: ...
    @property
    def durability(self) -> int: ...
    @property
    def deadline(self) -> Duration: ...
    @property
    def lifespan(self) -> Duration: ...
    @property
    def liveliness(self) -> int: ...
    @property
    def liveliness_lease_duration(self) -> Duration: ...
    @property
    def avoid_ros_namespace_conventions(self) -> bool: ...


def _time(duration: Duration) -> QosTime:
    sec, nsec = divmod(int(duration.nanoseconds), NS_PER_S)
    return QosTime(sec, nsec)


def _policy(kind: type[_Policy], value: int) -> _Policy:
    try:
        return kind(int(value))
    except ValueError:
        return kind["UNKNOWN"]


def offered_qos(profile: EndpointQos) -> Qos:
    """The ``rosbags`` QoS of a publisher's profile, policy by policy (rmw's enum values; one
    rosbags does not know is ``UNKNOWN``, as rmw_fastrtps reports the history of a remote
    writer), durations as seconds and nanoseconds (rmw's infinite one as 9223372036 s
    854775807 ns, as rosbag2 writes it)."""

    return Qos(
        _policy(QosHistory, profile.history),
        int(profile.depth),
        _policy(QosReliability, profile.reliability),
        _policy(QosDurability, profile.durability),
        _time(profile.deadline),
        _time(profile.lifespan),
        _policy(QosLiveliness, profile.liveliness),
        _time(profile.liveliness_lease_duration),
        bool(profile.avoid_ros_namespace_conventions),
    )


def jazzy_distro(metadata: str) -> str:
    """Bag metadata (YAML text as ``rosbags`` writes it) naming ``ROS_DISTRO`` as its ROS
    distribution."""
    return _DISTRO.sub(rf"\g<1>{ROS_DISTRO}", metadata)


class JazzyWriter(Writer):
    """A ``rosbags`` writer whose bag names ``jazzy`` as its ROS distribution: in the sqlite3
    ``schema`` table, in the MCAP ``rosbag2`` metadata record and in ``metadata.yaml``."""

    def open(self) -> None:
        """Create the bag (``rosbags.rosbag2.Writer.open``)."""
        super().open()
        conn = getattr(self.storage, "conn", None)
        if conn is not None:  # sqlite3: its schema row names the distribution
            conn.execute("UPDATE schema SET ros_distro = ?", (ROS_DISTRO,))
            conn.commit()

    def close(self) -> None:
        """Close the bag and write its metadata (``rosbags.rosbag2.Writer.close``)."""
        storage = self.storage
        if storage is not None:
            close_storage = storage.close

            def close_jazzy(version: int, metadata: str) -> None:
                close_storage(version, jazzy_distro(metadata))

            # the storage writer's close gets the metadata text the MCAP record (or the sqlite3
            # metadata row) holds; rosbags offers no other way to set its distribution
            storage.close = close_jazzy  # type: ignore[method-assign]
        super().close()
        tmp = self.metapath.with_suffix(".yaml.tmp")
        tmp.write_text(jazzy_distro(self.metapath.read_text("utf8")), "utf8")
        tmp.replace(self.metapath)
