"""Which parameters were active when: steady segments of a session from its parameter events.

Sources, in bag (log) time order, for the nodes in the motion topic's namespace:
``new_parameters`` give a value (the first value known of a parameter counts from the start of
the bag); ``changed_parameters`` / ``deleted_parameters`` change it at that moment (a parameter
first seen in a change is unknown before it). Only ``RELEVANT`` parameters split the session:
the controller's mode, kf and force limit, the wall's stiffness, damping, position and normal,
the observer's gain and output limit; the device's label it. A change takes effect:

- at its event's stamp when that lies within the motion's stamps (this suite's loop nodes stamp
  an event with the first sample the change applies to; so does any node's system clock beside
  a device stamping its samples with it);
- otherwise at the first motion sample logged at or after the event. Why: docs/design/recording.md.
"""

from __future__ import annotations

import copy
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from haptic_dob.bag.param_events import ParamEvent

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
    """Relevant parameters of one node that changed at bag (log) time ``time_ns``."""

    time_ns: int
    node: str
    values: dict[str, Any]
    stamp_ns: int | None = None  # the event's own stamp


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
            changes.append(Change(ev.time_ns, base, diff, ev.stamp_ns))
    return initial, changes


def split(
    recv_ns: np.ndarray,
    initial: Params,
    changes: list[Change],
    start_ns: int | None = None,
    period_ns: int | None = None,
) -> list[Segment]:
    """Cut samples into segments at changes.

    Sample ``i`` is stamped ``start_ns + i * period_ns`` (when given) and logged at
    ``recv_ns[i]`` (non-decreasing). A change stamped within the samples' stamps takes effect at
    the first sample stamped at or after it, any other at the first sample logged at or after
    it; several changes landing on the same sample make one boundary; changes after the last
    sample are ignored.
    """
    n = int(recv_ns.size)
    at: list[tuple[int, Change]] = []
    last_ns = None if start_ns is None or not period_ns else start_ns + (n - 1) * period_ns
    for ch in changes:
        stamp = ch.stamp_ns
        if (
            stamp is not None
            and start_ns is not None
            and period_ns
            and last_ns is not None
            and (start_ns <= stamp <= last_ns)
        ):
            i = -(-(stamp - start_ns) // period_ns)  # the first sample stamped at or after it
        else:
            i = int(np.searchsorted(recv_ns, ch.time_ns, side="left"))
        at.append((i, ch))
    at.sort(key=lambda item: item[0])  # stable: changes on one sample keep their order
    current = copy.deepcopy(initial)
    segs = [Segment(0, 0, n, copy.deepcopy(current))]
    for i, ch in at:
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
