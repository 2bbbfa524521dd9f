"""The nodes' parameter table of one launch: the config's node sections with ``--set`` applied,
what ``--record``, ``--pin`` and ``--cpu-latency`` add, the session's command token, and the
params file every node reads.

The table maps a node's name (or ``/**``, every node) to its flat ``{param: value}``.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from haptic_dob.core.command_authority import new_token
from haptic_dob.errors import InputError
from haptic_dob.nodes.registry import NODES
from haptic_dob.runtime import cpus
from haptic_dob.runtime.configs import urdf_beside
from haptic_dob.runtime.cpu_latency import NO_REQUEST
from haptic_dob.runtime.params import load_node_params
from haptic_dob.runtime.params_file import dump_params


def resolved_params(
    config: Path, sets: dict[str, dict[str, Any]], overlays: Sequence[Path] = ()
) -> dict[str, Any]:
    """The config's node sections (flattened), each ``overlays`` file's laid over them in order
    (``--params``: an identified model, an excitation), then ``--set``; keyed by node name. A
    relative ``urdf_path`` is taken from its file's directory where the file is there
    (``urdf/phantom_omni.urdf`` beside an installed config)."""
    out: dict[str, Any] = {}
    for path in (config, *overlays):
        try:
            sections = load_node_params(path)
        except (OSError, ValueError) as exc:
            raise InputError(f"{path}: {exc}") from None
        urdf_beside(sections, path)
        unknown = [n for n in sections if n != "/**" and n not in NODES]
        if unknown:
            raise InputError(
                f"{path} names unknown node(s) {', '.join(unknown)}; known: {', '.join(NODES)}"
            )
        for node, values in sections.items():
            out.setdefault(node, {}).update(values)
    for node, values in sets.items():
        out.setdefault(node, {}).update(values)
    return out


def add_recorder(params: dict[str, Any], output: str, storage: str) -> None:
    """A ``recorder_node`` writing ``output``, and the device waiting for it (loses nothing)."""
    if Path(output).exists():
        raise InputError(
            f"--record {output}: it exists already; the recorder never overwrites a bag"
        )
    params.setdefault("recorder_node", {}).update(output=output, storage=storage)
    # the node that starts the loop waits for it: the bridge to a driver, or the device
    device = params.setdefault("bridge_node" if "bridge_node" in params else "device_node", {})
    wait = list(device.get("wait_for", ["environment_node", "observer_node", "controller_node"]))
    if "recorder_node" not in wait:
        device["wait_for"] = [*wait, "recorder_node"]


def add_pinning(params: dict[str, Any]) -> str:
    """``--pin``: each loop node's ``cpu_affinity`` from the critical-path placement
    (``haptic_dob.runtime.cpus``), unless the config (its node section or ``/**``) or ``--set`` gave
    one; returns the plan's text."""
    try:
        assigned = cpus.placement([n for n in params if n != "/**"], cpus.available_cpus())
    except ValueError as exc:
        raise InputError(f"--pin: {exc}") from None
    common = params.get("/**", {}).get("cpu_affinity")
    for name, chosen in assigned.items():
        given = params[name].get("cpu_affinity", common)
        if given is not None and not isinstance(given, list):
            raise InputError(f"cpu_affinity of {name} must be a list of CPU numbers, got {given!r}")
        if given:
            assigned[name] = given
        else:
            params[name]["cpu_affinity"] = chosen
    return cpus.describe(assigned)


def add_cpu_latency(params: dict[str, Any], latency_us: int) -> None:
    """``--cpu-latency``: each loop node's ``cpu_latency_us``, unless the config or ``--set``
    gave a request (its node section or ``/**``; -1, no request, counts as not given)."""
    if not 0 <= latency_us <= 1_000_000:
        raise InputError(f"--cpu-latency {latency_us}: must be 0 to 1000000 us (0: idle CPUs poll)")
    common = params.get("/**", {}).get("cpu_latency_us")
    for name in (n for pair in cpus.PAIRS for n in pair if n in params):
        if params[name].get("cpu_latency_us", common) in (None, NO_REQUEST):
            params[name]["cpu_latency_us"] = latency_us


#: the nodes that take ``effort_command`` at a device end (the device bridge is one too)
DEVICE_ENDS = ("device_node", "bridge_node")
DEFAULT_SOURCE = "controller_node"


def add_command_tokens(params: dict[str, Any], started: Sequence[str]) -> list[str]:
    """One fresh command token for every device end in ``started`` and its ``command_source``,
    when that starts too and no token was given (config, ``--set``); what each device end takes
    its commands by, a line each. Names may carry a namespace (``slave/device_node``), where the
    source is looked for beside the device end."""
    common = params.get("/**", {})
    token = new_token()
    lines = []
    for name in started:
        ns, _, node = name.rpartition("/")
        if node not in DEVICE_ENDS:
            continue
        values = params.setdefault(name, {})

        def given(key: str, default: Any, values: dict[str, Any] = values) -> Any:
            return values.get(key, common.get(key, default))

        source = given("command_source", DEFAULT_SOURCE)
        source_key = f"{ns}/{source}" if ns else source
        if given("open_command_input", False):
            how = "from any publisher (open_command_input)"
        elif given("command_token", ""):
            how = f"only from {source}, by the command_token given"
        elif source_key in started:
            values["command_token"] = token
            params.setdefault(source_key, {})["command_token"] = token
            how = f"only from {source}, by this launch's command token"
        else:
            how = (
                f"only from {source}, which starts elsewhere: by its node name and GID in the "
                "graph (give both the same command_token to check every command)"
            )
        lines.append(f"{name} takes effort_command {how}")
    return lines


def write_params_file(params: dict[str, Any], directory: Path) -> Path:
    """A ``ros__parameters`` file any namespace matches (``/**/<node>`` keys), for this launch."""
    doc = {}
    for name, values in params.items():
        key = "/**" if name == "/**" else f"/**/{name}"
        doc[key] = {"ros__parameters": values}
    path = directory / "params.yaml"
    path.write_text(dump_params(doc), encoding="utf-8")
    return path
