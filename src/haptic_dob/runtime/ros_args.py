"""What a ROS command line gives a node's parameters, in rcl's order, ROS-free.

rcl (``rcl/src/rcl/arguments.c``, Jazzy) keeps every ``-p [NODE:]NAME:=VALUE`` and every
``--params-file FILE`` section in one table of entries keyed by node name (``/**`` for a bare
``-p``; the section's key for a file; ``NODE`` for ``-p NODE:NAME:=VALUE``, a plain name that
rclpy reads as ``/NODE``, the root namespace only), each entry where its name first appeared,
a later value of one entry replacing an earlier one. rclpy (``node.cpp``) then walks the entries
in that order and a later matching entry wins. So a node section of a params file wins over a
bare ``-p`` given before it, or given after it when the file has a ``/**`` section (the ``-p``
joins that earlier entry). ``shadowed`` tells which ``-p`` values a node does not get and why;
``configured_nodes`` which nodes the params files name (the container runs them).
"""

from __future__ import annotations

import re
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from haptic_dob.runtime.params import load_sections

#: ROS arguments that take a value (the next argument)
WITH_VALUE = frozenset(
    {"-p", "--param", "-r", "--remap", "--params-file", "--log-level", "--log-config-file",
     "-e", "--enclave", "--log-file-name"}
)  # fmt: skip


@dataclass(frozen=True)
class ParamRule:
    """One ``-p [NODE:]NAME:=VALUE`` (``node`` ``/**`` when bare)."""

    node: str
    name: str
    value: str

    @property
    def text(self) -> str:
        """The rule as typed."""
        prefix = "" if self.node == "/**" else f"{self.node}:"
        return f"-p {prefix}{self.name}:={self.value}"


@dataclass(frozen=True)
class Shadow:
    """A ``-p`` value a node does not get: the entry that wins (a file's section or a later
    rule), its file (None: the command line) and its value."""

    rule: ParamRule
    section: str
    source: str | None
    value: Any


def ros_rules(argv: Sequence[str]) -> list[ParamRule | str]:
    """The ``-p`` rules and ``--params-file`` paths (as ``str``) of ``argv``'s ``--ros-args``
    parts, in order."""
    out: list[ParamRule | str] = []
    in_ros, i = False, 0
    while i < len(argv):
        arg = argv[i]
        if arg == "--ros-args":
            in_ros = True
        elif arg == "--":
            in_ros = False
        elif in_ros and arg in WITH_VALUE and i + 1 < len(argv):
            i += 1
            if arg == "--params-file":
                out.append(argv[i])
            elif arg in ("-p", "--param"):
                rule = parse_rule(argv[i])
                if rule is not None:
                    out.append(rule)
        i += 1
    return out


def parse_rule(text: str) -> ParamRule | None:
    """``[NODE:]NAME:=VALUE`` as rcl reads it (NODE a plain name), None when it is not one."""
    head, sep, value = text.partition(":=")
    if not sep or not head:
        return None
    node, colon, name = head.rpartition(":")
    if colon and re.fullmatch(r"[A-Za-z_~][\w]*", node) is None:
        return None
    return ParamRule(node if colon else "/**", name, value)


def entries(rules: Sequence[ParamRule | str]) -> dict[str, dict[str, tuple[Any, ParamRule | str]]]:
    """rcl's table: node name -> {param: (value, where from)}, names in order of first
    appearance (a params file that does not load adds nothing: rcl refuses it itself)."""
    table: dict[str, dict[str, tuple[Any, ParamRule | str]]] = {}
    for rule in rules:
        if isinstance(rule, ParamRule):
            table.setdefault(rule.node, {})[rule.name] = (rule.value, rule)
            continue
        try:
            sections = load_sections(rule)
        except (OSError, ValueError):
            continue
        for key, params in sections.items():
            entry = table.setdefault(key, {})
            for name, value in params.items():
                entry[name] = (value, rule)
    return table


def matches(entry: str, fqn: str) -> bool:
    """Whether entry ``entry`` applies to the node ``fqn`` (rclpy's match: ``/*`` one name,
    ``/**`` any number; a name without a leading ``/`` is in the root namespace)."""
    name = entry if entry.startswith("/") else f"/{entry}"
    return re.fullmatch(name.replace("/*", r"(/\w+)"), fqn) is not None


def shadowed(argv: Sequence[str], fqn: str) -> list[Shadow]:
    """The ``-p`` values of ``argv`` that the node ``fqn`` does not get, in order."""
    rules = ros_rules(argv)
    winners: dict[str, tuple[str, Any, ParamRule | str]] = {}
    for key, params in entries(rules).items():
        if matches(key, fqn):
            for name, (value, source) in params.items():
                winners[name] = (key, value, source)
    out = []
    for rule in rules:
        if not isinstance(rule, ParamRule) or not matches(rule.node, fqn):
            continue
        key, value, source = winners[rule.name]
        if source is not rule and not (isinstance(source, ParamRule) and source.node == rule.node):
            out.append(Shadow(rule, key, source if isinstance(source, str) else None, value))
    return out


def shadow_line(shadows: Sequence[Shadow], fqn: str) -> str:
    """One line: which ``-p`` values a section overrode, and what to type instead."""
    node = fqn.rsplit("/", 1)[-1]
    said = ", ".join(
        f"{s.rule.text} (the {s.section} section{f' of {s.source}' if s.source else ''} "
        f"sets {s.rule.name}: {s.value!r})"
        for s in shadows
    )
    if fqn == f"/{node}":
        typed = " ".join(f"-p {node}:{s.rule.name}:={s.rule.value}" for s in shadows)
        advice = f"type {typed} after the last --params-file"
    else:
        values = ", ".join(f"{s.rule.name}: {s.rule.value}" for s in shadows)
        them = "it" if len(shadows) == 1 else "them"
        advice = (
            f"give {them} in a second --params-file after the first "
            f"({fqn}: {{ros__parameters: {{{values}}}}}): -p NODE: reaches the root namespace only"
        )
    return f"ignored {said}: a node's section wins over a bare -p (rcl's order); {advice}"


def configured_nodes(argv: Sequence[str], known: Sequence[str]) -> list[str]:
    """The nodes of ``known`` that ``argv``'s params files name, as ``NODE`` or ``NS/NODE``: a
    section ``/ns/NODE`` names ``ns/NODE``; ``/**/NODE`` or ``NODE`` names ``NODE`` unless a
    namespaced section names it too (a teleoperation config's sides)."""
    keys = [k for k, _ in entries([r for r in ros_rules(argv) if isinstance(r, str)]).items()]
    named: list[str] = []
    for key in keys:
        ns, _, node = key.strip("/").rpartition("/")
        if node in known and "*" not in ns and ns:
            named.append(f"{ns}/{node}")
    spaced = {n.rsplit("/", 1)[-1] for n in named}
    for key in keys:
        ns, _, node = key.strip("/").rpartition("/")
        if node in known and ns in ("", "**") and node not in spaced and node not in named:
            named.append(node)
    return named
