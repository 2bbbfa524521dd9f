"""Declarative parameters: one table per settings dataclass, used by nodes, YAML and batch runs.

A settings dataclass marks each field with keyword-only ``param(...)`` metadata (a one-line
description, unit, bounds, choices, read-only; details for the docs only). ``specs_of`` turns the
fields into ``ParamSpec`` rows, the only way rows are made; nodes declare them as ROS 2
parameters with descriptors (``haptic_dob.runtime.ros.params``), and ``build`` turns a mapping of
parameter values (a node's parameters or a ``ros__parameters`` YAML section) back into the
dataclass, so a node and a batch run read the same names, defaults and limits.
"""

from __future__ import annotations

import dataclasses
import math
import typing
from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from enum import Enum
from typing import Any, TypeVar

import yaml

ParamValue = bool | int | float | str | list[float] | list[str]

T = TypeVar("T")


@dataclass(frozen=True)
class ParamSpec:
    """One parameter: name, default, description, unit, limits and whether it is read-only."""

    name: str
    default: ParamValue
    description: str
    unit: str = ""
    min: float | None = None
    max: float | None = None
    choices: tuple[str, ...] = ()
    read_only: bool = False
    length: int | None = None  # arrays: the required number of elements, None = any
    items: type | None = None  # arrays: element type (float, int, str); None = the default's
    details: str = ""  # longer text for the generated docs only (not the ROS descriptor)

    @property
    def item_kind(self) -> type | None:
        """Element type of an array (float when the default is empty), None for scalars."""
        if self.kind is not list:
            return None
        if self.items is not None:
            return self.items
        d = list(self.default)  # type: ignore[arg-type]  # kind is list
        return type(d[0]) if d else float

    @property
    def kind(self) -> type:
        """Python type of the value: bool, int, float, str or list."""
        d = self.default
        return list if isinstance(d, (list, tuple)) else type(d)

    def full_description(self) -> str:
        """Description with unit, range and choices, as shown by ``ros2 param describe``."""
        parts = [self.description]
        if self.unit:
            parts.append(f"[{self.unit}]")
        if self.choices:
            parts.append("one of: " + ", ".join(self.choices))
        return " ".join(parts)

    def check(self, value: Any) -> str | None:
        """Return why ``value`` is refused, or None when it is acceptable."""
        kind = self.kind
        if kind is bool:
            if not isinstance(value, bool):
                return f"{self.name} must be a bool, got {value!r}"
            return None
        if kind is int:
            if isinstance(value, bool) or not isinstance(value, int):
                return f"{self.name} must be an integer, got {value!r}"
            return self._range(float(value))
        if kind is float:
            if isinstance(value, bool) or not isinstance(value, (int, float)):
                return f"{self.name} must be a number, got {value!r}"
            if not math.isfinite(float(value)):
                return f"{self.name} must be finite, got {value!r}"
            return self._range(float(value))
        if kind is str:
            if not isinstance(value, str):
                return f"{self.name} must be a string, got {value!r}"
            if self.choices and value not in self.choices:
                return f"{self.name} must be one of {', '.join(self.choices)}, got {value!r}"
            return None
        # arrays
        if isinstance(value, (str, bytes)) or not hasattr(value, "__len__"):
            return f"{self.name} must be an array, got {value!r}"
        items = list(value)
        if self.length is not None and len(items) != self.length:
            return f"{self.name} must have {self.length} elements, got {len(items)}"
        if self.item_kind is str:
            if not all(isinstance(v, str) for v in items):
                return f"{self.name} must be an array of strings"
            return None
        if self.item_kind is int:
            if not all(isinstance(v, int) and not isinstance(v, bool) for v in items):
                return f"{self.name} must be an array of integers, got {items!r}"
            return None
        for v in items:
            if isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v):
                return f"{self.name} must be an array of finite numbers, got {items!r}"
        for v in items:  # a range declared for an array holds for each element
            why = self._range(float(v))
            if why:
                return why
        return None

    def _range(self, x: float) -> str | None:
        unit = f" {self.unit}" if self.unit else ""
        if self.min is not None and x < self.min:
            return f"{self.name} must be >= {self.min:g}{unit}, got {x:g}"
        if self.max is not None and x > self.max:
            return f"{self.name} must be <= {self.max:g}{unit}, got {x:g}"
        return None


def param(
    *,
    description: str,
    unit: str = "",
    bounds: tuple[float | None, float | None] | None = None,
    choices: Sequence[str] = (),
    read_only: bool = False,
    details: str = "",
) -> dict[str, Any]:
    """Field metadata of a settings dataclass (``field(default=1.0, metadata=param(...))``).

    ``description``: one line, what the value is (the unit goes to ``unit``); ``bounds``: the
    closed range (lo, hi), either side None for none; ``details``: longer text that only the
    generated docs/parameters.md shows, not the ROS descriptor.
    """
    lo, hi = bounds if bounds is not None else (None, None)
    return {
        "param": {
            "description": description,
            "unit": unit,
            "min": lo,
            "max": hi,
            "choices": tuple(choices),
            "read_only": read_only,
            "details": details,
        }
    }


def specs_of(
    cls: type,
    prefix: str = "",
    *,
    read_only: bool | None = None,
    defaults: Mapping[str, Any] | None = None,
    about: str = "",
) -> list[ParamSpec]:
    """The ``ParamSpec`` rows of a settings dataclass's annotated fields, names prefixed.

    ``read_only`` overrides every field's own flag when given (structural groups); ``defaults``
    overrides the default of the fields it names (unprefixed: one group, a node's own default);
    ``about`` heads every description (``"about: description"``: a group used for another
    thing). An empty array's element type is its annotation's (``list[int]``).
    """
    overrides = dict(defaults or {})
    out = []
    for f in dataclasses.fields(cls):
        meta = f.metadata.get("param")
        if meta is None:
            continue
        if f.name in overrides:
            default = overrides.pop(f.name)
        elif f.default is not dataclasses.MISSING:
            default = f.default
        elif f.default_factory is not dataclasses.MISSING:
            default = f.default_factory()
        else:
            raise TypeError(f"{cls.__name__}.{f.name} is a parameter without a default")
        length = None
        if isinstance(default, tuple):
            default, length = list(default), len(default)
        elif isinstance(default, Enum):
            default = default.value
        items = _item_type(cls, f.name) if isinstance(default, list) and not default else None
        out.append(
            ParamSpec(
                name=prefix + f.name,
                default=default,
                description=f"{about}: {meta['description']}" if about else meta["description"],
                unit=meta["unit"],
                min=meta["min"],
                max=meta["max"],
                choices=meta["choices"],
                read_only=meta["read_only"] if read_only is None else read_only,
                length=length,
                items=items,
                details=meta["details"],
            )
        )
    if overrides:
        raise TypeError(f"{cls.__name__} has no parameter {', '.join(overrides)}")
    return out


def _item_type(cls: type, name: str) -> type | None:
    """The element type of array field ``name`` by its annotation (``list[int]``): int or str,
    None for float (the default's)."""
    hint = typing.get_type_hints(cls)[name]
    for arg in typing.get_args(hint) or (hint,):  # a union of list[X] and tuple[X, ...]
        items = typing.get_args(arg)
        if items and items[0] in (int, str):
            return items[0]  # type: ignore[no-any-return]  # int or str
    return None


def build(cls: type[T], values: Mapping[str, Any], prefix: str = "") -> T:
    """Instantiate settings dataclass ``cls`` from ``values`` (keys ``prefix + field``).

    Missing keys keep the dataclass defaults; arrays become tuples. Raises ``ValueError`` with the
    first refused value's reason.
    """
    kwargs: dict[str, Any] = {}
    for spec in specs_of(cls, prefix):
        if spec.name not in values:
            continue
        value = values[spec.name]
        if spec.kind is float and isinstance(value, int) and not isinstance(value, bool):
            value = float(value)
        reason = spec.check(value)
        if reason:
            raise ValueError(reason)
        if spec.kind is list:
            value = tuple(value)
        kwargs[spec.name[len(prefix) :]] = value
    return cls(**kwargs)


def values_of(obj: Any, prefix: str = "") -> dict[str, ParamValue]:
    """The parameter values of a settings dataclass instance (inverse of ``build``)."""
    out: dict[str, ParamValue] = {}
    for spec in specs_of(type(obj), prefix):
        v = getattr(obj, spec.name[len(prefix) :])
        if isinstance(v, Enum):
            v = v.value
        out[spec.name] = list(v) if isinstance(v, tuple) else v
    return out


def flatten(tree: Mapping[str, Any], prefix: str = "") -> dict[str, Any]:
    """Nested YAML mappings to ROS's dotted parameter names (``{"a": {"b": 1}}`` -> ``a.b``)."""
    out: dict[str, Any] = {}
    for k, v in tree.items():
        if isinstance(v, Mapping):
            out.update(flatten(v, f"{prefix}{k}."))
        else:
            out[f"{prefix}{k}"] = v
    return out


def load_sections(path: Any) -> dict[str, dict[str, Any]]:
    """A ``ros__parameters`` YAML file as ``{section key: {dotted name: value}}``, the keys as
    written (``/**``, ``/**/device_node``, ``/master/device_node``...).

    Raises ``ValueError`` (one line) when the file is not such a file; ``OSError`` when it cannot
    be read.
    """
    with open(path, encoding="utf-8") as fh:
        text = fh.read()
    try:
        doc = yaml.safe_load(text) or {}
    except yaml.YAMLError as exc:
        raise ValueError(f"{path} is not valid YAML: {' '.join(str(exc).split())}") from None
    if not isinstance(doc, dict):
        raise ValueError(f"{path} must map node names to ros__parameters")
    out: dict[str, dict[str, Any]] = {}
    for key, body in doc.items():
        params = body.get("ros__parameters") if isinstance(body, dict) else None
        if not isinstance(params, dict):
            raise ValueError(f"{path}: section {key!r} has no ros__parameters mapping")
        out[str(key)] = flatten(params)
    return out


def load_node_params(path: Any) -> dict[str, dict[str, Any]]:
    """A ``ros__parameters`` YAML file as ``{node name or "/**": {dotted name: value}}``.

    Node keys may be fully qualified (``/ns/device_node``, ``/**/device_node``); the last part is
    the name. Raises ``ValueError`` (one line) when the file is not such a file; ``OSError`` when
    it cannot be read.
    """
    return {
        ("/**" if key == "/**" else key.rsplit("/", 1)[-1]): params
        for key, params in load_sections(path).items()
    }


def node_view(nodes: Mapping[str, Mapping[str, Any]], name: str) -> dict[str, Any]:
    """The parameters node ``name`` gets: the ``/**`` values overlaid with its own section."""
    return {**dict(nodes.get("/**", {})), **dict(nodes.get(name, {}))}


def replace_groups(obj: Any, **groups: Any) -> Any:
    """A copy of a dataclass of settings groups: whole groups, or fields as ``group__field=v``."""
    cfg = dataclasses.replace(obj, **{k: v for k, v in groups.items() if "__" not in k})
    nested: dict[str, dict[str, Any]] = {}
    for key, value in groups.items():
        if "__" in key:
            group, name = key.split("__", 1)
            nested.setdefault(group, {})[name] = value
    for group, fields_ in nested.items():
        cfg = dataclasses.replace(
            cfg, **{group: dataclasses.replace(getattr(cfg, group), **fields_)}
        )
    return cfg
