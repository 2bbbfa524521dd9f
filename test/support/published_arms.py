"""Third-party arm descriptions from the ``example-robot-data`` package (``pip install -e
'.[arms]'``): where they are, and each arm's URDF, tip frame and a start posture away from
singularities. Tests skip them with a reason when the package is absent."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path


def example_robot_data() -> Path | None:
    """The ``robots`` folder of the example-robot-data package, when installed."""
    try:
        dist = metadata.distribution("example-robot-data")
    except metadata.PackageNotFoundError:
        return None
    path = Path(str(dist.locate_file("cmeel.prefix/share/example-robot-data/robots")))
    return path if path.is_dir() else None


ROBOTS = example_robot_data()
SKIP_REASON = "example-robot-data not installed (pip install -e '.[arms]')"
#: third-party arms: (URDF under robots/, tip frame, a start posture away from singularities)
ARMS = {
    "panda": (
        "panda_description/urdf/panda.urdf",
        "panda_hand_tcp",
        [0.2, -0.6, 0.1, -2.0, 0.1, 1.6, 0.8],
    ),
    "ur5": ("ur_description/urdf/ur5_robot.urdf", "tool0", [0.3, -1.2, 1.4, -1.6, -1.5, 0.2]),
    "z1": ("z1_description/urdf/z1.urdf", "gripperStator", [0.2, 1.0, -1.2, 0.3, 0.2, 0.1]),
    "kinova": (
        "kinova_description/robots/kinova.urdf",
        "j2s6s200_end_effector",
        [0.3, 3.4, 1.2, 0.5, 1.0, 0.2],
    ),
    "talos_arm": (
        "talos_data/robots/talos_left_arm.urdf",
        "gripper_left_base_link",
        [1.0, 1.1, 1.5, -1.0, -1.4, 0.1],
    ),
    "xarm7": ("xarm_description/urdf/xarm7.urdf", "link_eef", [0.1, -0.5, 0.1, 0.8, 0.1, 1.2, 0.1]),
}
