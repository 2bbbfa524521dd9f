"""Collect the joint states of some namespaces' devices into a file, run inside a network
namespace by ``test_teleop_lab_network.py``.

``python netns_collect.py OUT NS [NS ...]``: a ``collector`` node in each namespace (the devices
wait for it in lockstep) records ``joint_states`` until SIGTERM or SIGINT, then writes one JSON
line per message (namespace, stamp in ns, positions, efforts; floats exact) to OUT, and a line
``ready`` to stdout once every reader has matched its device.
"""

from __future__ import annotations

import json
import os
import signal
import sys
import threading

from haptic_msgs_py.stamps import stamp_ns
from haptic_msgs_py.topics import JOINT_STATES, SESSION_TOPICS
from support.rosgraph import Collector
from support.waits import wait_until


def main(out: str, namespaces: list[str]) -> int:
    stop = threading.Event()
    signal.signal(signal.SIGTERM, lambda *_: stop.set())
    signal.signal(signal.SIGINT, lambda *_: stop.set())
    env = dict(os.environ)
    topic = {JOINT_STATES: SESSION_TOPICS[JOINT_STATES]}
    cols = {ns: Collector(env, topic, namespace=ns) for ns in namespaces}
    try:
        if wait_until(lambda: all(c.matched() for c in cols.values()), 120, poll_s=0.05):
            print("ready", flush=True)
        stop.wait()
    finally:
        for c in cols.values():
            c.close()
    with open(out, "w", encoding="utf-8") as fh:
        for ns, col in cols.items():
            for m in col.messages(JOINT_STATES):
                row = {
                    "ns": ns,
                    "stamp": stamp_ns(m),
                    "position": [float(x) for x in m.position],
                    "effort": [float(x) for x in m.effort],
                }
                fh.write(json.dumps(row) + "\n")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1], sys.argv[2:]))
