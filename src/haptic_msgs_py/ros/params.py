"""Declare a node's ``ParamSpec`` table as ROS 2 parameters and guard every change.

Each spec becomes a parameter with a descriptor (description with unit, a range, read-only where
structural). Changes go through two steps so nothing half-applies: the on-set callback checks
each value (type, range, choices) and lets the node validate the whole proposed set (building
its settings object); only if everything passes does the post-set callback hand the node the
new, consistent snapshot. Refusals carry the reason ``ros2 param set`` prints.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Any

from rcl_interfaces.msg import (
    FloatingPointRange,
    IntegerRange,
    ParameterDescriptor,
    SetParametersResult,
)
from rclpy.node import Node
from rclpy.parameter import Parameter

from haptic_msgs_py.params import ParamSpec


def descriptor(spec: ParamSpec) -> ParameterDescriptor:
    """The ``ParameterDescriptor`` of a spec (dynamic typing: 2 and 2.0 are both accepted)."""
    d = ParameterDescriptor(
        name=spec.name,
        description=spec.full_description(),
        read_only=spec.read_only,
        dynamic_typing=True,
    )
    if spec.choices:
        d.additional_constraints = "one of: " + ", ".join(spec.choices)
    if spec.kind is float and spec.min is not None and spec.max is not None:
        d.floating_point_range = [
            FloatingPointRange(from_value=float(spec.min), to_value=float(spec.max), step=0.0)
        ]
    elif spec.kind is int and spec.min is not None and spec.max is not None:
        d.integer_range = [IntegerRange(from_value=int(spec.min), to_value=int(spec.max), step=0)]
    return d


def unset_as_empty(spec: ParamSpec, value: Any) -> Any:
    """An array given as ``[]`` (YAML or ``-p name:=[]``) reaches rclpy untyped, as "not set"
    (None): for an array parameter that is the empty list."""
    return [] if value is None and spec.kind is list else value


def normalise(spec: ParamSpec, value: Any) -> Any:
    """Python value of the spec's kind (ints for float specs become floats, arrays lists)."""
    value = unset_as_empty(spec, value)
    if spec.kind is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if spec.kind is list:
        return [float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in value]
    return value


class ParameterTable:
    """A node's parameters from specs, with whole-snapshot validation and atomic application.

    Args:
        node: the node that owns the parameters.
        specs: the parameter rows.
        validate: builds the node's settings from a full mapping of proposed values; raises
            ``ValueError`` (its message is the refusal reason).
        apply: receives the settings ``validate`` built, after the change is accepted.
    """

    def __init__(
        self,
        node: Node,
        specs: Iterable[ParamSpec],
        validate: Callable[[Mapping[str, Any]], Any] | None = None,
        apply: Callable[[Any], None] | None = None,
    ) -> None:
        self.node = node
        self.specs = {s.name: s for s in specs}
        self._validate = validate
        self._apply = apply
        self._pending: Any = None
        self._declaring = True
        self.values: dict[str, Any] = {}
        node.add_on_set_parameters_callback(self._on_set)
        node.add_post_set_parameters_callback(self._post_set)
        declared = node.declare_parameters(
            "", [(s.name, _ros_default(s), descriptor(s)) for s in self.specs.values()]
        )
        for p in declared:
            self.values[p.name] = normalise(self.specs[p.name], p.value)
        self._declaring = False
        self.settings = validate(self.values) if validate else None

    def set_validator(
        self,
        validate: Callable[[Mapping[str, Any]], Any],
        apply: Callable[[Any], None] | None = None,
    ) -> Any:
        """Install the whole-snapshot validator later (when it needs objects built from the
        start-up values); validates the current values now and returns the settings."""
        self._validate, self._apply = validate, apply
        self.settings = validate(self.values)
        return self.settings

    def _on_set(self, params: list[Parameter]) -> SetParametersResult:
        proposed = dict(self.values)
        for p in params:
            spec = self.specs.get(p.name)
            if spec is None:
                continue
            if spec.read_only and not self._declaring:
                return SetParametersResult(successful=False, reason=f"{p.name} is read-only")
            reason = spec.check(unset_as_empty(spec, p.value))
            if reason:
                return SetParametersResult(successful=False, reason=reason)
            proposed[p.name] = normalise(spec, p.value)
        if self._declaring or self._validate is None:
            return SetParametersResult(successful=True)
        try:
            self._pending = (proposed, self._validate(proposed))
        except ValueError as exc:
            return SetParametersResult(successful=False, reason=str(exc))
        return SetParametersResult(successful=True)

    def _post_set(self, params: list[Parameter]) -> None:
        if self._declaring:
            return
        if self._pending is None:  # no validator: take the values as they are
            for p in params:
                if p.name in self.specs:
                    self.values[p.name] = normalise(self.specs[p.name], p.value)
            return
        self.values, self.settings = self._pending
        self._pending = None
        if self._apply is not None:
            self._apply(self.settings)


def _ros_default(spec: ParamSpec) -> Any:
    """Default in a form rclpy accepts for declaration (typed arrays need a homogeneous list)."""
    if spec.kind is list:
        return list(spec.default)  # type: ignore[arg-type]
    return spec.default
