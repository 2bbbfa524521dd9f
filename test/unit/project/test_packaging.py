"""ROS conventions on a pip install: ament index, package.xml, AMENT_PREFIX_PATH, config."""

from __future__ import annotations

import os
import subprocess
import sys
import xml.etree.ElementTree as ET
from pathlib import Path

import pytest

PACKAGES = ("haptic_dob", "haptic_sim", "haptic_msgs_py")


def fresh_python(code: str, env: dict[str, str] | None = None) -> str:
    """Run ``code`` in a new interpreter of this environment, AMENT_PREFIX_PATH unset."""
    e = {k: v for k, v in os.environ.items() if k != "AMENT_PREFIX_PATH"} | (env or {})
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, env=e, timeout=60
    )
    assert out.returncode == 0, out.stderr
    return out.stdout.strip()


def test_ament_prefix_is_set_without_exporting_anything() -> None:
    assert fresh_python("import os; print(os.environ['AMENT_PREFIX_PATH'])") == sys.prefix


def test_a_sourced_ros_prefix_is_kept() -> None:
    value = fresh_python(
        "import os; print(os.environ['AMENT_PREFIX_PATH'])", {"AMENT_PREFIX_PATH": "/opt/ros/jazzy"}
    )
    assert value.split(os.pathsep) == ["/opt/ros/jazzy", sys.prefix]


def test_ament_index_lists_the_packages() -> None:
    listed = fresh_python(
        "from ament_index_python.packages import get_packages_with_prefixes as g; "
        "print(' '.join(sorted(g())))"
    ).split()
    for pkg in PACKAGES:
        assert pkg in listed


@pytest.mark.parametrize("pkg", PACKAGES)
def test_package_xml_is_installed_and_names_the_package(pkg: str) -> None:
    share = fresh_python(
        "from ament_index_python.packages import get_package_share_directory as g; "
        f"print(g({pkg!r}))"
    )
    xml = Path(share) / "package.xml"
    assert xml.is_file()
    root = ET.parse(xml).getroot()
    assert root.findtext("name") == pkg
    assert root.find("export/build_type").text == "ament_python"


def test_config_files_are_installed(root: Path) -> None:
    share = fresh_python(
        "from ament_index_python.packages import get_package_share_directory as g; "
        "print(g('haptic_dob'))"
    )
    for cfg in (root / "config").glob("*.yaml"):
        assert (Path(share) / "config" / cfg.name).read_text() == cfg.read_text()


def test_constraints_pin_every_dependency(root: Path) -> None:
    pins = {
        line.split("==")[0].lower()
        for line in (root / "constraints.txt").read_text().splitlines()
        if "==" in line and not line.startswith("#")
    }
    for dep in (
        "ros-jazzy-rclpy",
        "ros-jazzy-common-interfaces",
        "ros-jazzy-rmw-fastrtps-cpp",
        "numpy",
        "scipy",
        "matplotlib",
        "pin",
        "rosbags",
    ):
        assert dep in pins
