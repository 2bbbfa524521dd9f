"""The graph as a ROS user starts it, in a namespace, from the params files, read back the way
``ros2 param get`` reads (rclpy's ``AsyncParameterClient`` over the nodes' parameter services):

- ``ros2 run haptic_dob container <the loop's nodes> --ros-args -r __ns:=/slide1 --params-file
  config/slide_sim.yaml --params-file mine.yaml``: every node section of both files applies (the
  second file wins), the loop closes, ``joint_states`` carries ``base_link``, and a recorder that
  subscribes as ``ros2 bag record`` does (in the root namespace, once it has seen the
  publishers) gets every sample from 0 when the device's ``wait_for`` names ``/rosbag2_recorder``;
- the overrides docs/running.md documents, through a ``controller_node`` process each.
"""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
import rclpy
import yaml
from ament_index_python.packages import get_package_prefix
from rclpy.context import Context
from rclpy.executors import SingleThreadedExecutor
from rclpy.parameter import parameter_value_to_python
from rclpy.parameter_client import AsyncParameterClient
from rclpy.task import Future

from haptic_dob.runtime.params import load_node_params, node_view
from support.rosgraph import Process, isolated_env, random_domains
from support.waits import answered, wait_until

pytestmark = [pytest.mark.multiprocess]

ROOT = Path(__file__).resolve().parents[2]
CONFIG = ROOT / "config" / "slide_sim.yaml"
LOOP = ("device_node", "environment_node", "observer_node", "controller_node")
N = 1000  # samples of the run (1 s at 1 kHz, in lockstep)
MS = 1_000_000


def executable(package: str, name: str) -> str:
    """``<prefix>/lib/<package>/<name>``, as ``ros2 run`` finds it."""
    return str(Path(get_package_prefix(package)) / "lib" / package / name)


class Probe:
    """An rclpy context on one domain, spun in this thread: ``ros2 param get`` and a recorder."""

    def __init__(self, domain: int) -> None:
        self.context = Context()
        rclpy.init(context=self.context, args=[], domain_id=domain)
        self.node = rclpy.create_node("param_probe", context=self.context)
        self.ex = SingleThreadedExecutor(context=self.context)
        self.ex.add_node(self.node)

    def until(self, condition: Callable[[], bool], timeout: float) -> bool:
        """Spin until ``condition`` (a hang guard, not a timing bound)."""
        return wait_until(condition, timeout, step=lambda: self.ex.spin_once(timeout_sec=0.05))

    def ask(self, send: Callable[[], Future]) -> Future:
        """The future of a request ``send()`` makes, spun until answered (sent again while the
        answer does not come, ``waits.answered``; 60 s hang guard)."""
        return answered(send, 60.0, step=lambda: self.ex.spin_once(timeout_sec=0.05))

    def get(self, node: str, names: list[str]) -> dict[str, Any]:
        """The values of those of ``names`` that ``node`` declares (``ros2 param list``, then
        ``ros2 param get``: the service answers nothing when one name is not declared)."""
        client = AsyncParameterClient(self.node, node)
        assert client.wait_for_services(timeout_sec=120.0), f"no parameter services of {node}"
        listed = self.ask(client.list_parameters)
        assert listed.done(), f"no answer from {node}"
        declared = set(listed.result().result.names)
        names = [n for n in names if n in declared]
        future = self.ask(lambda: client.get_parameters(names))
        assert future.done(), f"no answer from {node}"
        values = future.result().values
        return {n: parameter_value_to_python(v) for n, v in zip(names, values, strict=True)}

    def close(self) -> None:
        self.ex.shutdown()
        rclpy.try_shutdown(context=self.context)


class LateRecorder:
    """Subscribes as ``ros2 bag record --topics`` does: its node ``/rosbag2_recorder`` first,
    the subscriptions once it has seen a publisher of each topic (looking every 0.1 s)."""

    def __init__(self, probe: Probe, namespace: str) -> None:
        from sensor_msgs.msg import JointState
        from std_msgs.msg import Float64MultiArray

        from haptic_dob.bag.cdr import command_label_stamp_ns
        from haptic_msgs_py.ros.qos import RECORD

        self.node = rclpy.create_node("rosbag2_recorder", context=probe.context)
        probe.ex.add_node(self.node)
        topics = (f"{namespace}/joint_states", f"{namespace}/effort_command")
        assert probe.until(lambda: all(self.node.count_publishers(t) for t in topics), 60.0)
        self.joints: list[tuple[int, str]] = []
        self.commands: list[int | None] = []

        def on_joints(msg: Any) -> None:
            st = msg.header.stamp
            self.joints.append((st.sec * 10**9 + st.nanosec, msg.header.frame_id))

        js, cmd = topics
        self.node.create_subscription(JointState, js, on_joints, RECORD)
        self.node.create_subscription(
            Float64MultiArray,
            cmd,
            lambda data: self.commands.append(command_label_stamp_ns(data)),
            RECORD,
            raw=True,
        )


def expected(files: list[Path], node: str) -> dict[str, Any]:
    """What ``node`` gets from the params files, later files winning."""
    out: dict[str, Any] = {}
    for f in files:
        out.update(node_view(load_node_params(f), node))
    return out


def assert_values(got: dict[str, Any], want: dict[str, Any], own: set[str], node: str) -> None:
    for name, value in want.items():
        if name not in got:
            assert name not in own, f"{node}: {name} of its own section was not declared"
            continue  # a /** value for other nodes
        have = list(got[name]) if isinstance(value, list) else got[name]
        if isinstance(value, (str, bool)):
            assert have == value, (node, name, have)
        else:
            assert have == pytest.approx(value), (node, name, have, value)


def test_a_namespaced_graph_from_the_params_files_runs_with_every_section(tmp_path: Path) -> None:
    mine = tmp_path / "mine.yaml"
    mine.write_text(
        yaml.safe_dump(
            {
                "/**/device_node": {
                    "ros__parameters": {
                        "duration_s": N / 1000.0,
                        "start_delay_s": 2.0,
                        "wait_for": [*LOOP[1:], "/rosbag2_recorder"],
                    }
                },
                "/**/controller_node": {"ros__parameters": {"kf": 0.5}},
            }
        )
    )
    env = isolated_env()
    files = [CONFIG, mine]
    ros_args = ["--ros-args", "-r", "__ns:=/slide1"]
    for f in files:
        ros_args += ["--params-file", str(f)]
    graph = Process(
        [executable("haptic_dob", "container"), *LOOP, *ros_args], env, tmp_path / "graph.log"
    )
    probe = Probe(int(env["ROS_DOMAIN_ID"]))
    try:
        for node in LOOP:  # the device holds sample 0 for /rosbag2_recorder: all still up
            want = expected(files, node)
            own = {name for f in files for name in load_node_params(f).get(node, {})}
            got = probe.get(f"/slide1/{node}", list(want))
            assert_values(got, want, own, node)
        assert probe.get("/slide1/controller_node", ["kf"]) == {"kf": 0.5}  # mine.yaml won
        rec = LateRecorder(probe, "/slide1")
        assert probe.until(lambda: graph.proc.poll() is not None, 120.0), graph.output()
        assert graph.proc.returncode == 0, graph.output()
        # what the graph sent before it ended is in the reader's queue (acknowledged): take it
        probe.until(lambda: len(rec.commands) > N and len(rec.joints) > N, 10.0)
    finally:
        graph.stop()
        probe.close()
    stamps = sorted({s for s, _ in rec.joints})
    assert stamps == [k * MS for k in range(N + 1)], graph.output()[-2000:]  # none lost at start
    assert {frame for _, frame in rec.joints} == {"base_link"}
    assert sorted(set(rec.commands)) == stamps  # the loop closed: a command for every sample


OVERRIDES = {
    "bare -p loses to the node section": (["-p", "kf:=25"], 0.0),
    "-p node:name": (["-p", "controller_node:kf:=25"], 25.0),
    "a second params file": (["--params-file", "MINE"], 25.0),
}


def test_the_documented_overrides_through_node_processes(tmp_path: Path) -> None:
    """docs/running.md, Parameters on the ROS command line: each way, one ``controller_node``
    process started with ``--params-file config/slide_sim.yaml`` (the root namespace), kf read
    back through the parameter services."""
    mine = tmp_path / "mine.yaml"
    mine.write_text("/**/controller_node:\n  ros__parameters:\n    kf: 25.0\n")
    runs = []
    domains = random_domains(len(OVERRIDES))  # one each: a process on another's domain answers
    try:
        for (case, (extra, want)), domain in zip(OVERRIDES.items(), domains, strict=True):
            env = isolated_env(domain)
            args = [str(mine) if a == "MINE" else a for a in extra]
            argv = [executable("haptic_dob", "controller_node"), "--ros-args"]
            argv += ["--params-file", str(CONFIG), *args]
            log = tmp_path / f"{len(runs)}.log"
            runs.append((case, want, Process(argv, env, log), int(env["ROS_DOMAIN_ID"])))
        for case, want, proc, domain in runs:
            probe = Probe(domain)
            try:
                got = probe.get("/controller_node", ["kf", "mode"])
            finally:
                probe.close()
            assert got == {"kf": want, "mode": "OL"}, (case, proc.output())
    finally:
        for *_, proc, _ in runs:
            assert proc.stop() in (0, None), proc.output()
