"""``ros__parameters`` YAML written so that rcl reads every value as this suite means it.

rcl's parser types an unquoted scalar by its look, where PyYAML (which reads the suite's configs)
keeps a string: a command token ``4111751691456e08`` would reach a node as a double, ``0123`` as
an integer, and the node refuses it. It also refuses YAML aliases. ``dump_params`` writes every
string value double-quoted and no aliases; keys stay plain.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any

import yaml


class _Quoted(str):
    """A string value, written double-quoted."""


class _Dumper(yaml.SafeDumper):  # type: ignore[misc]  # PyYAML ships without stubs here
    """YAML without anchors: rcl's parser refuses aliases (nodes share values, such as lists)."""

    def ignore_aliases(self, data: Any) -> bool:
        return True


def _represent_quoted(dumper: yaml.SafeDumper, text: _Quoted) -> Any:
    return dumper.represent_scalar("tag:yaml.org,2002:str", str(text), style='"')


_Dumper.add_representer(_Quoted, _represent_quoted)


def _quoted(value: Any) -> Any:
    if isinstance(value, Mapping):
        return {key: _quoted(v) for key, v in value.items()}
    if isinstance(value, list | tuple):
        return [_quoted(v) for v in value]
    if isinstance(value, str):
        return _Quoted(value)
    return value


def dump_params(doc: Mapping[str, Any]) -> str:
    """``doc`` (section key -> ``{"ros__parameters": {...}}``) as YAML text for rcl."""
    return str(yaml.dump(_quoted(doc), Dumper=_Dumper, sort_keys=False))
