"""Segments from parameter events, and the fast CDR readers against rosbags' deserializer."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.bag.cdr import decode_vectors
from haptic_dob.bag.param_events import ParamEvent
from haptic_dob.bag.segments import parameter_history, split
from haptic_msgs_py import wire


def ev(t: int, node: str, values: dict, new: bool = False) -> ParamEvent:
    return ParamEvent(t, node, values, (), frozenset(values) if new else frozenset())


def test_declarations_count_from_the_start_and_changes_split() -> None:
    events = [
        ev(5, "/controller_node", {"use_sim_time": False}, new=True),
        ev(6, "/controller_node", {"mode": "OL", "kf": 0.0}, new=True),  # declared later
        ev(7, "/environment_node", {"stiffness_n_per_m": 800.0}, new=True),
        ev(100, "/controller_node", {"mode": "DOB", "kf": 1.0}),
        ev(150, "/controller_node", {"mode": "DOB"}),  # no change
        ev(200, "/environment_node", {"stiffness_n_per_m": 1600.0, "other": 3}),
        ev(210, "/ns/controller_node", {"mode": "CL"}),  # another namespace
        ev(220, "/device_node", {"duration_s": 4.0}),  # not a rendering node
    ]
    initial, changes = parameter_history(events, "")
    assert initial == {
        "controller_node": {"mode": "OL", "kf": 0.0},
        "environment_node": {"stiffness_n_per_m": 800.0},
    }
    assert [(c.time_ns, c.node, c.values) for c in changes] == [
        (100, "controller_node", {"mode": "DOB", "kf": 1.0}),
        (200, "environment_node", {"stiffness_n_per_m": 1600.0}),
    ]
    recv = np.arange(0, 300, 10)  # samples received every 10 ns from 0 to 290
    segs = split(recv, initial, changes)
    assert [(s.start, s.stop) for s in segs] == [(0, 10), (10, 20), (20, 30)]
    assert [s.value("controller_node", "mode") for s in segs] == ["OL", "DOB", "DOB"]
    assert [s.value("environment_node", "stiffness_n_per_m") for s in segs] == [800, 800, 1600]
    _, ns_changes = parameter_history(events, "/ns")
    assert [c.values for c in ns_changes] == [{"mode": "CL"}]


def test_a_change_is_unknown_before_and_boundaries_merge() -> None:
    events = [
        ev(91, "/controller_node", {"mode": "CL"}),  # first seen in a change (no snapshot)
        ev(100, "/controller_node", {"kf": 2.0}),  # lands on the same sample
        ev(999, "/controller_node", {"kf": 3.0}),  # after the last sample
    ]
    initial, changes = parameter_history(events, "")
    assert initial == {}
    segs = split(np.arange(0, 300, 10), initial, changes)
    assert [(s.start, s.stop) for s in segs] == [(0, 10), (10, 30)]
    assert segs[0].value("controller_node", "mode") is None
    assert segs[1].params == {"controller_node": {"mode": "CL", "kf": 2.0}}
    assert len(segs[1].changed) == 2
    # changes before the first sample only set the starting parameters
    segs = split(np.arange(200, 300, 10), initial, changes[:2])
    assert len(segs) == 1 and segs[0].params["controller_node"] == {"mode": "CL", "kf": 2.0}


def test_an_event_stamped_on_the_samples_timeline_splits_at_its_stamp() -> None:
    """A loop node stamps its event with the first sample it applies to: the split is exact
    even when the event reached the recorder seconds late (repaired in transit)."""
    late = ParamEvent(260, "/controller_node", {"mode": "DOB"}, (), frozenset(), 1_000_055)
    wall = ParamEvent(150, "/environment_node", {"stiffness_n_per_m": 900.0}, (), frozenset(), 17)
    initial, changes = parameter_history([late, wall], "")
    recv = np.arange(0, 300, 10)  # sample i received at 10 i, stamped 1_000_000 + 10 i
    segs = split(recv, initial, changes, start_ns=1_000_000, period_ns=10)
    # the controller's change at stamp 1_000_055 -> sample 6 (stamped 1_000_060), although
    # received after sample 25; the environment's stamp (17) is off the timeline: by receipt
    assert [(s.start, s.stop) for s in segs] == [(0, 6), (6, 15), (15, 30)]
    assert [s.value("controller_node", "mode") for s in segs] == [None, "DOB", "DOB"]
    assert segs[2].value("environment_node", "stiffness_n_per_m") == 900.0
    # without the samples' stamps, both split by receipt (the old behaviour)
    assert [(s.start, s.stop) for s in split(recv, initial, changes)] == [
        (0, 15),
        (15, 26),
        (26, 30),
    ]


@pytest.mark.parametrize("frames", [("base_link",) * 3, ("a", "base_link", "xyz_long_frame")])
def test_fast_vector_reader_matches_the_deserializer(frames: tuple[str, ...]) -> None:
    datas = []
    want = []
    for i, frame in enumerate(frames):
        msg = wire.wrench_stamped(frame)
        msg.header.stamp.sec, msg.header.stamp.nanosec = i, 1000 * i
        f = msg.wrench.force
        f.x, f.y, f.z = 1.5 * i, -2.0 * i, 0.25 + i
        datas.append(wire.encode(msg))
        want.append((i * 1_000_000_000 + 1000 * i, (f.x, f.y, f.z)))
    stamps, values = decode_vectors(datas, "geometry_msgs/msg/WrenchStamped", (0, 1, 2))
    assert stamps.tolist() == [w[0] for w in want]
    assert values.tolist() == [list(w[1]) for w in want]
    _, z = decode_vectors(datas, "geometry_msgs/msg/WrenchStamped", (2,))
    assert z[:, 0].tolist() == [w[1][2] for w in want]
