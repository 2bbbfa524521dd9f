"""Typed results to JSON and back: dataclasses as objects, lists as arrays, ``None`` as null.

``to_json`` writes a dataclass's fields in order, plus the properties it names in
``JSON_DERIVED`` (written for the reader, ignored when loading). ``from_json`` rebuilds a dataclass
from its field types (``float``, ``int``, ``str``, ``bool``, ``X | None``, ``list[X]``,
``dict[str, X]``, nested dataclasses, ``Any`` as is) and raises ``ValueError`` naming the first
value that does not fit, so a results file of another format fails with one line.
"""

from __future__ import annotations

import types
from dataclasses import fields, is_dataclass
from typing import Any, TypeVar, Union, cast, get_args, get_origin, get_type_hints

T = TypeVar("T")


def to_json(value: Any) -> Any:
    """JSON-ready form of a result: dataclasses become objects (fields, then ``JSON_DERIVED``)."""
    if is_dataclass(value) and not isinstance(value, type):
        out = {f.name: to_json(getattr(value, f.name)) for f in fields(value)}
        for name in getattr(value, "JSON_DERIVED", ()):
            out[name] = to_json(getattr(value, name))
        return out
    if isinstance(value, list | tuple):
        return [to_json(v) for v in value]
    if isinstance(value, dict):
        return {str(k): to_json(v) for k, v in value.items()}
    return value


def from_json(cls: type[T], data: Any) -> T:
    """Rebuild a ``cls`` (a dataclass) from what ``to_json`` wrote; ``ValueError`` if it differs."""
    return cast(T, _decode(cls, data, cls.__name__))


def _decode(tp: Any, data: Any, where: str) -> Any:
    origin = get_origin(tp)
    if tp is Any:
        return data
    if origin in (Union, types.UnionType):
        if data is None and type(None) in get_args(tp):
            return None
        (inner,) = (a for a in get_args(tp) if a is not type(None))  # X | None only
        return _decode(inner, data, where)
    if origin is list:
        (item,) = get_args(tp)
        return [_decode(item, v, f"{where}[{i}]") for i, v in enumerate(_expect(data, list, where))]
    if origin is dict:
        _, item = get_args(tp)
        return {k: _decode(item, v, f"{where}.{k}") for k, v in _expect(data, dict, where).items()}
    if is_dataclass(tp):
        return _decode_dataclass(tp, _expect(data, dict, where), where)
    if tp is float:
        if isinstance(data, bool) or not isinstance(data, int | float):
            raise ValueError(f"{where}: expected a number, got {data!r}")
        return float(data)
    if tp in (int, str, bool):
        if type(data) is not tp:
            raise ValueError(f"{where}: expected {tp.__name__}, got {data!r}")
        return data
    raise TypeError(f"{where}: no JSON form for {tp!r}")


def _decode_dataclass(tp: Any, data: dict[str, Any], where: str) -> Any:
    hints = get_type_hints(tp)
    names = [f.name for f in fields(tp) if f.init]
    unknown = set(data) - set(names) - set(getattr(tp, "JSON_DERIVED", ()))
    if unknown:
        raise ValueError(f"{where}: unknown field(s) {', '.join(sorted(unknown))}")
    values = {n: _decode(hints[n], data[n], f"{where}.{n}") for n in names if n in data}
    try:
        return tp(**values)
    except TypeError as exc:  # a required field is missing
        raise ValueError(f"{where}: {exc}") from None


def _expect(data: Any, kind: type, where: str) -> Any:
    if not isinstance(data, kind):
        raise ValueError(f"{where}: expected a JSON {'array' if kind is list else 'object'}")
    return data
