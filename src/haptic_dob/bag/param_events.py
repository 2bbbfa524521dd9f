"""Recorded ``rcl_interfaces/msg/ParameterEvent`` messages as plain values (``ParamEvent``)."""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

PARAMETER_EVENT = "rcl_interfaces/msg/ParameterEvent"


@dataclass(frozen=True)
class ParamEvent:
    """One ``rcl_interfaces/msg/ParameterEvent`` as recorded."""

    time_ns: int  # bag (log) time
    node: str  # fully qualified node name, e.g. /controller_node
    values: dict[str, Any]  # new and changed parameters
    deleted: tuple[str, ...]
    new: frozenset[str]  # the names in new_parameters (declarations, the recorder's snapshot)
    stamp_ns: int | None = None  # the event's own stamp (loop nodes: the sample it applies from)


def _param_value(v: Any) -> Any:
    """Python value of a ``rcl_interfaces/msg/ParameterValue``."""
    t = int(v.type)
    if t == 1:
        return bool(v.bool_value)
    if t == 2:
        return int(v.integer_value)
    if t == 3:
        return float(v.double_value)
    if t == 4:
        return str(v.string_value)
    if t == 5:
        return [int(b) for b in v.byte_array_value]
    if t == 6:
        return [bool(b) for b in v.bool_array_value]
    if t == 7:
        return [int(i) for i in v.integer_array_value]
    if t == 8:
        return [float(d) for d in v.double_array_value]
    if t == 9:
        return [str(s) for s in v.string_array_value]
    return None


def param_event(msg: Any, time_ns: int) -> ParamEvent:
    """A ``ParamEvent`` of a decoded ParameterEvent message logged at ``time_ns``."""
    values = {p.name: _param_value(p.value) for p in msg.new_parameters}
    values.update({p.name: _param_value(p.value) for p in msg.changed_parameters})
    deleted = tuple(p.name for p in msg.deleted_parameters)
    new = frozenset(p.name for p in msg.new_parameters)
    stamp = int(msg.stamp.sec) * 1_000_000_000 + int(msg.stamp.nanosec)
    return ParamEvent(time_ns, str(msg.node), values, deleted, new, stamp)
