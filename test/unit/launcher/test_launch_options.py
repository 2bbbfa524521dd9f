"""haptic-launch's options: the command line parsed into ``LaunchOptions``, and the checks that
turn option values into launch inputs (namespace, ``--set``, discovery). No process starts."""

from __future__ import annotations

import pytest

from haptic_dob.cli.launch import parse_options
from haptic_dob.errors import InputError
from haptic_dob.launcher.options import (
    LaunchOptions,
    comma_list,
    network_env,
    normalize_namespace,
    parse_sets,
    say_session,
)


def test_a_bare_config_gives_the_default_options() -> None:
    assert parse_options(["slide_sim"]) == LaunchOptions(config="slide_sim")


def test_every_flag_reaches_its_option() -> None:
    opts = parse_options(
        [
            "slide_sim",
            "--namespace=lab/a",
            "--set",
            "device_node:seed=3",
            "--set",
            "controller_node:kf=1",
            "--group",
            "device_node,controller_node",
            "--duration",
            "2.5",
            "--stop-timeout",
            "1",
            "--executor",
            "single",
            "--only",
            "device_node,,controller_node",
            "--network",
            "subnet",
            "--peers",
            "h1,h2",
            "--record",
            "bag",
            "--record-storage",
            "sqlite3",
            "--rt-priority",
            "10",
            "--pin",
            "--cpu-latency",
            "0",
        ]
    )
    assert opts == LaunchOptions(
        config="slide_sim",
        namespace="lab/a",
        sets=("device_node:seed=3", "controller_node:kf=1"),
        groups=("device_node,controller_node",),
        stop_timeout=1.0,
        duration=2.5,
        executor="single",
        only=("device_node", "controller_node"),
        network="subnet",
        peers=("h1", "h2"),
        record="bag",
        record_storage="sqlite3",
        rt_priority=10,
        pin=True,
        cpu_latency_us=0,
    )
    assert parse_options(["x", "--composed"]).composed
    assert parse_options(["x", "--processes"]).processes


@pytest.mark.parametrize(
    "argv", [[], ["x", "--network", "wan"], ["x", "--executor", "multi"], ["x", "--bogus"]]
)
def test_bad_arguments_exit_2_with_one_error_line(argv, capsys) -> None:
    with pytest.raises(SystemExit) as stop:
        parse_options(argv)
    assert stop.value.code == 2
    assert capsys.readouterr().err.splitlines()[-1].startswith("ERROR: ")


@pytest.mark.parametrize(
    ("text", "items"), [("", ()), ("a", ("a",)), ("a,b", ("a", "b")), (",a,,b,", ("a", "b"))]
)
def test_comma_lists_drop_empty_items(text: str, items: tuple[str, ...]) -> None:
    assert comma_list(text) == items


@pytest.mark.parametrize(
    ("given", "expected"),
    [("", ""), ("slide1", "/slide1"), ("/slide1", "/slide1"), ("lab/slide_1/", "/lab/slide_1")],
)
def test_namespace_is_made_absolute(given: str, expected: str) -> None:
    assert normalize_namespace(given) == expected


@pytest.mark.parametrize("bad", ["1slide", "sl ide", "a//b", "a-b"])
def test_invalid_namespace_is_refused(bad: str) -> None:
    with pytest.raises(InputError, match="not a valid ROS namespace"):
        normalize_namespace(bad)


def test_sets_are_yaml_values_per_node() -> None:
    sets = parse_sets(
        ["controller_node:kf=1.5", "controller_node:mode=DOB", "device_node:wait_for=[a, b]"]
    )
    assert sets == {
        "controller_node": {"kf": 1.5, "mode": "DOB"},
        "device_node": {"wait_for": ["a", "b"]},
    }
    assert parse_sets(["observer_node:note=a=b"]) == {"observer_node": {"note": "a=b"}}


@pytest.mark.parametrize(
    ("item", "message"),
    [
        ("controller_node", "--set needs NODE:PARAM=VALUE"),
        ("controller_node:kf", "--set needs NODE:PARAM=VALUE"),
        (":kf=1", "--set needs NODE:PARAM=VALUE"),
        ("controller_node:=1", "--set needs NODE:PARAM=VALUE"),
        ("pilot_node:kf=1", "--set names unknown node 'pilot_node'"),
        ("controller_node:kf=[1", "the value is not valid YAML"),
        ("device_node:slide.mass_kg=0.5", "the simulated slide's physics is plant.mass_kg"),
    ],
)
def test_a_bad_set_is_one_error(item: str, message: str) -> None:
    with pytest.raises(InputError, match=message.replace("[", r"\[")):
        parse_sets([item])


def test_discovery_stays_on_this_host_unless_asked() -> None:
    assert network_env("localhost", []) == {"ROS_AUTOMATIC_DISCOVERY_RANGE": "LOCALHOST"}
    assert network_env("subnet", ["h1", "h2"]) == {
        "ROS_AUTOMATIC_DISCOVERY_RANGE": "SUBNET",
        "ROS_STATIC_PEERS": "h1;h2",
    }
    with pytest.raises(InputError, match="--peers needs --network subnet"):
        network_env("localhost", ["h1"])
    with pytest.raises(InputError, match="--network must be one of localhost, subnet"):
        network_env("wan", [])


def test_the_launch_says_its_domain_and_discovery_then_the_command_authority(
    monkeypatch, capsys
) -> None:
    monkeypatch.setenv("ROS_DOMAIN_ID", "42")
    say_session(network_env("localhost", []), ["device_node takes effort_command ..."])
    assert capsys.readouterr().err.splitlines() == [
        "haptic-launch: domain 42, discovery localhost",
        "haptic-launch: device_node takes effort_command ...",
    ]
