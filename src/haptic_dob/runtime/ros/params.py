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

from haptic_dob.runtime.params import ParamSpec


def ros_type(spec: ParamSpec) -> Parameter.Type:
    """The ROS parameter type a spec is declared with (arrays by their element type)."""
    if spec.kind is list:
        return {str: Parameter.Type.STRING_ARRAY, int: Parameter.Type.INTEGER_ARRAY}.get(
            spec.item_kind or float, Parameter.Type.DOUBLE_ARRAY
        )
    return {
        bool: Parameter.Type.BOOL,
        int: Parameter.Type.INTEGER,
        str: Parameter.Type.STRING,
    }.get(spec.kind, Parameter.Type.DOUBLE)


def descriptor(spec: ParamSpec) -> ParameterDescriptor:
    """The ``ParameterDescriptor`` of a spec: its type fixed (``ros2 param describe`` shows it
    whatever is set later), description with unit, range, choices, read-only."""
    d = ParameterDescriptor(
        name=spec.name,
        type=ros_type(spec).value,
        description=spec.full_description(),
        read_only=spec.read_only,
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
    (None) or as an empty byte array: for an array parameter that is the empty list."""
    if spec.kind is list and (value is None or (hasattr(value, "__len__") and not len(value))):
        return []
    return value


def normalise(spec: ParamSpec, value: Any) -> Any:
    """Python value of the spec's kind (ints for float specs become floats, arrays lists)."""
    value = unset_as_empty(spec, value)
    if spec.kind is float and isinstance(value, int) and not isinstance(value, bool):
        return float(value)
    if spec.kind is list and spec.item_kind is float:
        return [float(v) if isinstance(v, int) and not isinstance(v, bool) else v for v in value]
    if spec.kind is list:
        return list(value)
    return value


def typed(spec: ParamSpec, param: Parameter) -> Parameter:
    """``param`` as the spec's declared type when it converts without loss (an integer for a
    double, integers for doubles, ``[]`` for any array), as rclcpp converts ``-p kf:=25`` for a
    double; anything else unchanged (rclpy then refuses the wrong type and keeps the value)."""
    want = ros_type(spec)
    if param.type_ == want:
        return param
    value = unset_as_empty(spec, param.value)
    if spec.kind is list and not value:
        return Parameter(param.name, want, [])
    if want is Parameter.Type.DOUBLE and param.type_ is Parameter.Type.INTEGER:
        return Parameter(param.name, want, float(value))
    if want is Parameter.Type.DOUBLE_ARRAY and param.type_ is Parameter.Type.INTEGER_ARRAY:
        return Parameter(param.name, want, [float(v) for v in value])
    return param


class ParameterTable:
    """A node's parameters from specs, with whole-snapshot validation and atomic application.

    Construction declares the rows and reads their start-up values (``values``); the node then
    builds its objects from them and installs its validator with ``set_validator``. Until then a
    change is checked row by row only.

    Args:
        node: the node that owns the parameters.
        specs: the parameter rows.
        accepted: called with the changed parameters once a change (after the declaration) is
            accepted, before rclpy publishes its event (a loop node stamps the event).
    """

    def __init__(
        self,
        node: Node,
        specs: Iterable[ParamSpec],
        accepted: Callable[[list[Parameter]], None] | None = None,
    ) -> None:
        self.node = node
        self.specs = {s.name: s for s in specs}
        self._validate: Callable[[Mapping[str, Any]], Any] | None = None
        self._apply: Callable[[Any], None] | None = None
        self._accepted = accepted
        self._pending: Any = None
        self._declaring = True
        self.values: dict[str, Any] = {}
        self.settings: Any = None
        node.add_pre_set_parameters_callback(self._typed)
        node.add_on_set_parameters_callback(self._on_set)
        node.add_post_set_parameters_callback(self._post_set)
        # values given at start-up (params file, -p) are converted like later sets are; rclpy
        # cannot declare an empty typed array (it re-reads [] as a byte array): such a
        # parameter is declared by its default or type and set empty right after
        overrides = node._parameter_overrides
        empty = []
        for name, spec in self.specs.items():
            if name in overrides:
                given = typed(spec, overrides[name])
                if spec.kind is list and given.type_ is ros_type(spec) and not given.value:
                    del overrides[name]
                    empty.append(name)
                else:
                    overrides[name] = given
        declared = node.declare_parameters(
            "", [(s.name, _ros_default(s), descriptor(s)) for s in self.specs.values()]
        )
        # (read-only lifted for that set: describe_parameter hands out the node's descriptor)
        for p in declared:
            if p.type_ is Parameter.Type.NOT_SET or p.name in empty:
                d = node.describe_parameter(p.name)
                read_only, d.read_only = d.read_only, False
                try:
                    node.set_parameters([Parameter(p.name, ros_type(self.specs[p.name]), [])])
                finally:
                    d.read_only = read_only
        for name in self.specs:
            self.values[name] = normalise(self.specs[name], node.get_parameter(name).value)
        self._declaring = False

    def set_validator(
        self,
        validate: Callable[[Mapping[str, Any]], Any],
        apply: Callable[[Any], None] | None = None,
    ) -> Any:
        """Install the whole-snapshot validator, once the node's objects are built from the
        start-up values: ``validate`` builds the settings from a full mapping of proposed values
        (``ValueError``: the refusal's reason), ``apply`` receives them once the change is
        accepted. Validates the current values now and returns the settings."""
        self._validate, self._apply = validate, apply
        self.settings = validate(self.values)
        return self.settings

    def _typed(self, params: list[Parameter]) -> list[Parameter]:
        """Pre-set: values of another type that convert without loss take the declared type."""
        return [typed(self.specs[p.name], p) if p.name in self.specs else p for p in params]

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
        if self._declaring:
            return SetParametersResult(successful=True)
        if self._validate is not None:
            try:
                self._pending = (proposed, self._validate(proposed))
            except ValueError as exc:
                return SetParametersResult(successful=False, reason=str(exc))
        if self._accepted is not None:
            self._accepted(params)
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


def _ros_default(spec: ParamSpec) -> Parameter.Type | Any:
    """Default in a form rclpy accepts for declaration: an empty array by its type."""
    if spec.kind is list:
        return list(spec.default) or ros_type(spec)  # type: ignore[arg-type]  # kind is list
    return spec.default
