"""Reading a recorded teleoperation graph back (``haptic-teleop --bag``): what the channel's
messages carry for the record, where the session's config comes from, and the refusals. The
recorded graph itself against the batch run: test_graph_teleop_bag.py."""

from __future__ import annotations

import dataclasses

import pytest

from haptic_dob.bag.errors import BagError
from haptic_dob.bag.param_events import ParamEvent
from haptic_dob.bag.write import write_session_bag
from haptic_dob.nodes.channel_node import from_wire, to_wire
from haptic_dob.teleop.ends import PortMessage
from haptic_dob.teleop.graph import (
    NAMESPACES,
    SIDE_NODES,
    TO_SLAVE,
    load_teleop_sections,
    node_values,
)
from haptic_sim.cli.teleop import main
from haptic_sim.teleop.bag import session_config
from haptic_sim.teleop.config import TeleopConfig
from support.bagdata import msd_record, session_params


def test_the_link_message_carries_the_ports_energy_book_and_silence() -> None:
    m = PortMessage(7, (1.0, 2.0, 3.0), (4.0, 5.0, 6.0), (7.0, 8.0, 9.0), 0.5, 0.25, 0.125, True)
    wire = to_wire(m)
    assert wire.name == ("x", "y", "z", "energy", "silent")
    assert from_wire(wire) == m
    assert from_wire(to_wire(m._replace(peer_silent=False))).peer_silent is False


def events_of(sections, drop: str = "") -> list[ParamEvent]:
    """Each node's declared parameters as the recorder's snapshot holds them."""
    out = []
    for ns in NAMESPACES:
        for node in SIDE_NODES[ns]:
            name = f"/{ns}/{node}"
            if name != drop:
                values = node_values(sections, ns, node)
                out.append(ParamEvent(len(out), name, values, (), frozenset(values)))
    return out


def test_the_config_is_the_nodes_recorded_parameters(root) -> None:
    path = root / "config" / "teleop_sim.yaml"
    sections = load_teleop_sections(path)
    got = session_config(events_of(sections), "bag")
    want = TeleopConfig.from_yaml(path)
    assert (got.channel, got.teleop, got.contact, got.loop) == (
        want.channel,
        want.teleop,
        want.contact,
        want.loop,
    )
    with pytest.raises(BagError, match="lacks the parameters of /slave/channel_node"):
        session_config(events_of(sections, drop="/slave/channel_node"), "bag")


def test_a_real_time_recording_is_refused_in_one_line(root) -> None:
    """Each side of a real-time graph stamps its samples by its own system clock."""
    sections = load_teleop_sections(root / "config" / "teleop_sim.yaml")
    events = events_of(sections)
    device = next(e for e in events if e.node == "/master/device_node")
    events[events.index(device)] = dataclasses.replace(
        device, values={**device.values, "clock_mode": "realtime"}
    )
    with pytest.raises(BagError, match=r"a real-time recording .* record the session in lockstep"):
        session_config(events, "bag")


def test_a_bag_of_one_loop_is_refused_in_one_line(tmp_path, capsys) -> None:
    bag = tmp_path / "loop"
    x, f, v = msd_record(0.2, 1000.0, 0.4, 2.0, 800.0)
    write_session_bag(bag, x, f, 1000.0, session_params(), velocity=v)
    assert main(["--bag", str(bag)]) == 2
    err = capsys.readouterr().err.strip()
    assert err.startswith("ERROR:") and "not a recorded teleoperation graph" in err
    assert "\n" not in err


@pytest.mark.parametrize(
    "extra", [["--delay-ms", "5"], ["teleop_sim"], ["--set", "/**/device_node:seed=1"]]
)
def test_run_options_are_refused_with_a_bag(tmp_path, capsys, extra) -> None:
    assert main(["--bag", str(tmp_path), *extra]) == 2
    assert "not with --bag" in capsys.readouterr().err


def test_haptic_analyze_points_a_teleop_bag_to_haptic_teleop(tmp_path, capsys) -> None:
    from haptic_dob.bag.write import open_writer, vector_template
    from haptic_dob.cli.analyze import main as analyze
    from haptic_msgs_py.wire import TYPESTORE

    bag = tmp_path / "teleop"
    writer = open_writer(bag, "mcap")
    pose, js = "geometry_msgs/msg/PoseStamped", "sensor_msgs/msg/JointState"
    for topic, kind in (("/master/ee_pose", pose), ("/slave/ee_pose", pose), (TO_SLAVE, js)):
        conn = writer.add_connection(topic, kind, typestore=TYPESTORE)
        if kind == pose:
            writer.write(conn, 1, vector_template(pose).fill(0, (0.0, 0.0, 0.0)))
    writer.close()
    assert analyze([str(bag)]) == 2
    err = capsys.readouterr().err
    assert "several motion topics" in err and f"haptic-teleop --bag {bag}" in err
