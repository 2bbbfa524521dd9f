"""Which parameters were active when: steady segments of a session from its parameter events.

Sources, in bag (receive) time order, for the nodes in the motion topic's namespace:

- ``new_parameters`` (the recorder's snapshot of every node, or a node declaring its parameters
  while ``ros2 bag record`` ran) give a parameter's value; the first value known of a
  parameter this way counts from the start of the bag (nothing was recorded about it before);
- ``changed_parameters`` / ``deleted_parameters`` change them at that moment (a parameter first
  seen in a change is unknown before it).

Only the parameters that shape the rendering (``RELEVANT``) split the session: the controller's
mode, kf and force limit, the wall's stiffness, damping, position and normal, the observer's
gain and output limit. A change splits the samples at the first motion sample the recorder
received at or after the parameter event (both carry the recorder's receive time; the event's
own wall-clock stamp is not comparable with the loop's sample stamps, which in lockstep run
faster than real time). The recorder receives the event and the samples through one executor,
in the order they arrived, so the split lands within a few samples of the first cycle the node
computed with the new value.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from haptic_dob.bag.reader import ParamEvent

#: node name -> the parameters that define a segment (the device's are read-only: they never
#: split a session, they label it -- the hand's protocol, the plant's friction, the seed)
RELEVANT: dict[str, tuple[str, ...]] = {
    "controller_node": ("mode", "kf", "max_force_n"),
    "environment_node": ("stiffness_n_per_m", "damping_n_s_per_m", "position", "normal"),
    "observer_node": ("gain", "output_limit"),
    "device_node": (
        "clock_mode",
        "seed",
        "slide.coulomb_n",
        "hand.behaviour",
        "hand.stiffness_n_per_m",
        "hand.offset_m",
        "hand.perturbation_n",
        "hand.perturbation_at_s",
        "hand.perturbation_s",
    ),
}

Params = dict[str, dict[str, Any]]  # node name -> parameter -> value


@dataclass(frozen=True)
class Change:
    """Relevant parameters of one node that changed at bag time ``time_ns``."""

    time_ns: int
    node: str
    values: dict[str, Any]


@dataclass
class Segment:
    """Samples ``[start, stop)`` of a record with one set of parameters."""

    index: int
    start: int
    stop: int
    params: Params
    changed: list[Change] = field(default_factory=list)  # what started it (empty: the first)

    @property
    def size(self) -> int:
        """Samples in the segment."""
        return self.stop - self.start

    def value(self, node: str, name: str) -> Any:
        """A parameter's value in this segment (None if unknown)."""
        return self.params.get(node, {}).get(name)


def parameter_history(events: list[ParamEvent], namespace: str) -> tuple[Params, list[Change]]:
    """(initial parameters, later changes) of the ``RELEVANT`` nodes in ``namespace``."""
    state: Params = {}
    initial: Params = {}
    changes: list[Change] = []
    for ev in sorted(events, key=lambda e: e.time_ns):
        ns, _, base = ev.node.rpartition("/")
        if ns != namespace or base not in RELEVANT:
            continue
        names = RELEVANT[base]
        vals = {k: v for k, v in ev.values.items() if k in names}
        vals.update({k: None for k in ev.deleted if k in names})
        known = state.setdefault(base, {})
        diff = {}
        for k, v in vals.items():
            if k not in known and k in ev.new:  # first declared value: it held from the start
                known[k] = v
                initial.setdefault(base, {})[k] = v
            elif k not in known or known[k] != v:
                diff[k] = v
        if diff:
            known.update(diff)
            changes.append(Change(ev.time_ns, base, diff))
    return initial, changes


def split(recv_ns: np.ndarray, initial: Params, changes: list[Change]) -> list[Segment]:
    """Cut samples (their non-decreasing receive times ``recv_ns``) into segments at changes.

    A change takes effect at the first sample received at or after it; several changes landing
    on the same sample make one boundary; changes after the last sample are ignored.
    """
    n = int(recv_ns.size)
    current = copy.deepcopy(initial)
    segs = [Segment(0, 0, n, copy.deepcopy(current))]
    for ch in changes:
        i = int(np.searchsorted(recv_ns, ch.time_ns, side="left"))
        if i >= n:
            break
        current.setdefault(ch.node, {}).update(ch.values)
        last = segs[-1]
        if i == last.start:
            last.params = copy.deepcopy(current)
            if last.index > 0:
                last.changed.append(ch)
            continue
        last.stop = i
        segs.append(Segment(len(segs), i, n, copy.deepcopy(current), [ch]))
    return segs
