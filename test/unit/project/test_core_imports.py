"""The numeric core never imports rclpy: every non-node module loads in a process without it."""

from __future__ import annotations

import ast
import pathlib
import pkgutil
import re
import subprocess
import sys

import haptic_dob
import haptic_msgs_py
import haptic_sim

ROS_PARTS = ("nodes", "ros", "launch")


def core_modules() -> list[str]:
    """Every module of the three packages outside the node/ROS subpackages."""
    names = []
    for pkg in (haptic_msgs_py, haptic_dob, haptic_sim):
        names.append(pkg.__name__)
        for info in pkgutil.walk_packages(pkg.__path__, pkg.__name__ + "."):
            parts = info.name.split(".")
            if any(p in ROS_PARTS or p.endswith("_node") for p in parts[1:]):
                continue
            names.append(info.name)
    return names


def test_there_are_core_modules() -> None:
    mods = core_modules()
    assert "haptic_dob.core.observers.disturbance" in mods and "haptic_sim.slide.session" in mods


def test_core_modules_do_not_import_rclpy() -> None:
    code = (
        "import importlib, sys\n"
        f"mods = {core_modules()!r}\n"
        "for m in mods:\n"
        "    importlib.import_module(m)\n"
        "bad = sorted(k for k in sys.modules if k == 'rclpy' or k.startswith('rclpy.'))\n"
        "print(','.join(bad))\n"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == "", f"rclpy imported by the core: {out.stdout.strip()}"


# scripts -> haptic_sim -> haptic_dob -> haptic_msgs_py: a package imports only those after it
LAYERS = ("haptic_sim", "haptic_dob", "haptic_msgs_py")


def imported_packages(path: pathlib.Path) -> set[str]:
    """The project packages a source file imports (any import statement, at any depth)."""
    tree = ast.parse(path.read_text(encoding="utf-8"))
    found = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            found.update(alias.name.split(".")[0] for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.level == 0:
            found.add(node.module.split(".")[0])
    return found & set(LAYERS)


def test_layers_have_no_arrow_back() -> None:
    src = pathlib.Path(haptic_dob.__file__).resolve().parents[1]
    back = []
    for i, pkg in enumerate(LAYERS):
        above = set(LAYERS[:i])
        for path in sorted((src / pkg).rglob("*.py")):
            for name in sorted(imported_packages(path) & above):
                back.append(f"{path.relative_to(src)} imports {name}")
    assert back == []


def named_modules(path: pathlib.Path) -> set[str]:
    """Top-level packages of the suite that ``path`` names in a module path string
    (``"pkg.module"`` or ``"pkg.module:Class"``, the form importlib and entry points take)."""
    found = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Constant) and isinstance(node.value, str):
            m = re.fullmatch(r"(\w+)(\.\w+)+(:\w+)?", node.value)
            if m:
                found.add(m.group(1))
    return found & set(LAYERS)


def test_no_arrow_back_through_a_module_path_either() -> None:
    """A lower layer does not import an upper one by name at run time either (importlib): the
    simulator's device node is registered as an entry point, not named by the control side."""
    src = pathlib.Path(haptic_dob.__file__).resolve().parents[1]
    back = []
    for i, pkg in enumerate(LAYERS):
        above = set(LAYERS[:i])
        for path in sorted((src / pkg).rglob("*.py")):
            for name in sorted(named_modules(path) & above):
                back.append(f"{path.relative_to(src)} names a module of {name}")
    assert back == []


def test_the_registry_finds_every_node_through_its_entry_point() -> None:
    from haptic_dob.nodes.registry import NODES, START_ORDER, node_class

    assert list(NODES) == list(START_ORDER)
    assert NODES["device_node"].package == "haptic_sim"
    assert node_class("device_node").__name__ == "DeviceNode"
    assert {NODES[n].package for n in START_ORDER if n != "device_node"} == {"haptic_dob"}


def test_messages_package_holds_no_runtime() -> None:
    """haptic_msgs_py holds topics, QoS, values, wire format and conversions, not the runtime."""
    names = {m.name.rsplit(".", 1)[-1] for m in pkgutil.walk_packages(haptic_msgs_py.__path__)}
    assert not names & {"params", "cpus", "cpu_latency", "entry", "spin"}
