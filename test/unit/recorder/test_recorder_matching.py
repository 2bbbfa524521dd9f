"""The start handshake: a recorder says when its readers have matched; the device waits for it."""

from __future__ import annotations

from haptic_dob.recorder.counts import RecordingCounts
from haptic_dob.recorder.matching import ReaderMatch, loop_started, reported_progress, unmatched
from haptic_msgs_py.topics import PROGRESS_NOT_MATCHED_NS
from haptic_sim.device.recorder_gate import RecorderGate


def test_a_reader_is_matched_when_it_sees_every_writer_its_graph_shows() -> None:
    assert unmatched([ReaderMatch("/wrench_desired", 1, 1), ReaderMatch("/ee_pose", 0, 0)]) == []
    # not a loop topic: its writer may offer a QoS a reliable reader never matches (best effort)
    assert unmatched([ReaderMatch("/camera/points", 0, 1)]) == []
    # the graph shows the writer, this reader has not matched it yet (the race the handshake is for)
    assert unmatched([ReaderMatch("/wrench_desired", 0, 1)]) == ["/wrench_desired"]
    assert unmatched([ReaderMatch("/ns/ee_pose", 1, 2)]) == ["/ns/ee_pose"]


def test_joint_states_needs_a_device_even_when_the_graph_shows_none() -> None:
    assert unmatched([ReaderMatch("/slide1/joint_states", 0, 0)]) == ["/slide1/joint_states"]
    assert unmatched([ReaderMatch("/slide1/joint_states", 1, 0)]) == []


def test_the_recorder_says_not_matched_only_before_the_first_loop_sample() -> None:
    counts = RecordingCounts()
    js = counts.add_topic("/joint_states", "sensor_msgs/msg/JointState")
    events = counts.add_topic("/diagnostics", "diagnostic_msgs/msg/DiagnosticArray")
    late = [ReaderMatch("/joint_states", 0, 1)]
    assert reported_progress(0, counts, late) == PROGRESS_NOT_MATCHED_NS
    assert reported_progress(0, counts, [ReaderMatch("/joint_states", 1, 1)]) == 0
    events.wrote(1_795_000_000_000_000_000, 1_000_000)  # a node's clock stamp: not a loop sample
    assert not loop_started(counts)
    assert reported_progress(0, counts, late) == PROGRESS_NOT_MATCHED_NS
    js.wrote(0, 1_000_000)  # sample 0 written: a reader that goes later does not stop the loop
    assert loop_started(counts)
    assert reported_progress(0, counts, late) == 0


def test_the_device_waits_for_every_recorder_to_say_it_matched() -> None:
    gate = RecorderGate()
    assert not gate.unmatched(0)
    assert gate.unmatched(1)  # a recorder in the graph that has not reported
    gate.report("/recorder_node", PROGRESS_NOT_MATCHED_NS, 0.0)
    assert gate.unmatched(1)
    assert gate.written_ns is None  # "not matched" is no progress: it holds no command
    gate.report("/recorder_node", 0, 0.1)
    assert not gate.unmatched(1)
    assert gate.unmatched(2)
    gate.report("/collector", 0, 0.1)
    assert not gate.unmatched(2)
    gate.report("/recorder_node", PROGRESS_NOT_MATCHED_NS, 0.2)  # restarted, matching again
    assert gate.unmatched(2)
