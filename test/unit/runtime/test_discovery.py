"""The DDS domain and discovery range read from an environment as rcl reads it, what haptic-launch
says of it, and when a real device warns."""

from __future__ import annotations

import pytest

from haptic_dob.runtime.discovery import Discovery, exposure_warning


@pytest.mark.parametrize(
    ("env", "domain", "given", "range_", "peers"),
    [
        ({}, "0", False, "SUBNET", ()),
        ({"ROS_DOMAIN_ID": "42"}, "42", True, "SUBNET", ()),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, "0", False, "LOCALHOST", ()),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SYSTEM_DEFAULT"}, "0", False, "SYSTEM_DEFAULT", ()),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "subnet"}, "0", False, "LOCALHOST", ()),  # rcl: invalid
        ({"ROS_STATIC_PEERS": "hostb;10.0.0.2;"}, "0", False, "SUBNET", ("hostb", "10.0.0.2")),
        ({"ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF", "ROS_STATIC_PEERS": "b"}, "0", False, "OFF", ()),
        ({"ROS_LOCALHOST_ONLY": "1", "ROS_STATIC_PEERS": "b"}, "0", False, "LOCALHOST", ()),
        ({"ROS_LOCALHOST_ONLY": "0"}, "0", False, "SUBNET", ()),
    ],
)
def test_the_environment_is_read_as_rcl_reads_it(env, domain, given, range_, peers) -> None:
    assert Discovery.of(env) == Discovery(domain, given, range_, peers)


def test_the_launch_says_the_domain_the_range_and_the_peers() -> None:
    local = Discovery.of({"ROS_DOMAIN_ID": "42", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"})
    assert local.describe() == "domain 42, discovery localhost"
    subnet = Discovery.of({"ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET", "ROS_STATIC_PEERS": "b"})
    assert subnet.describe() == (
        "domain 0 (ROS_DOMAIN_ID unset: the default), discovery subnet, peers b"
    )


@pytest.mark.parametrize(
    ("env", "reasons"),
    [
        ({}, ["default domain 0", "discovery subnet with no ROS_STATIC_PEERS"]),
        ({"ROS_DOMAIN_ID": "0", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, ["domain 0"]),
        ({"ROS_DOMAIN_ID": "7"}, ["discovery subnet with no ROS_STATIC_PEERS"]),
        ({"ROS_DOMAIN_ID": "7", "ROS_STATIC_PEERS": "hostb"}, []),
        ({"ROS_DOMAIN_ID": "7", "ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}, []),
        ({"ROS_DOMAIN_ID": "7", "ROS_AUTOMATIC_DISCOVERY_RANGE": "OFF"}, []),
    ],
)
def test_a_real_device_warns_in_one_line_on_domain_0_or_an_open_subnet(env, reasons) -> None:
    line = exposure_warning(env)
    if not reasons:
        assert line is None
        return
    assert line is not None and "\n" not in line
    assert all(r in line for r in reasons), line
