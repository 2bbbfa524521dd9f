"""Any serial arm from a URDF, computed with pinocchio (sensorless tip-force estimation).

The joint-space vectors follow ``joint_names`` (default: the joints that move ``tip_frame``, from
the root out); every other joint of the URDF is locked at zero. Revolute, continuous (used through
its angle) and prismatic joints can be coordinates; mimic joints follow their master; fixed joints,
grippers outside the chain and meshes need nothing (see ``_pinocchio_urdf``). The end-effector
point is the origin of ``tip_frame``; its Jacobian is the linear part of the frame Jacobian in the
base frame's axes (pinocchio's ``LOCAL_WORLD_ALIGNED``). Gravity is 9.81 m/s^2 along -z of the
URDF's root.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field
from pathlib import Path

from haptic_dob.core.models._pinocchio import PinocchioModel
from haptic_dob.core.models._pinocchio_urdf import add_payload, urdf_model
from haptic_dob.runtime.params import param


class UrdfModel(PinocchioModel):
    """A serial arm from a URDF file or XML string (``DeviceModel``).

    Args:
        urdf: URDF XML text (e.g. a ``robot_description``) or the path of a ``.urdf`` file.
        tip_frame: the link or frame whose origin is the end-effector point.
        joint_names: the joints to use, in this order (default: the chain to ``tip_frame``).
        gravity: False leaves gravity out of the model.
        viscous, coulomb, coulomb_speed, armature: as ``PinocchioModel``'s, scalar or per
            joint; None: each joint's from the URDF (``<dynamics damping friction>``,
            ``<haptic_dob:dynamics coulomb_speed armature>``; 0 where it has none).
        payload_kg: a point mass (kg) at ``tip_frame``'s origin that the URDF does not have.

    Raises ``ValueError`` with a clear message for a bad URDF, an unknown frame or joint, or a
    joint that cannot be a coordinate (floating, planar, a mimic joint named in ``joint_names``).
    """

    def __init__(
        self,
        urdf: str | Path,
        tip_frame: str,
        joint_names: Sequence[str] | None = None,
        *,
        gravity: bool = True,
        viscous: float | Sequence[float] | None = None,
        coulomb: float | Sequence[float] | None = None,
        coulomb_speed: float | Sequence[float] | None = None,
        armature: float | Sequence[float] | None = None,
        payload_kg: float = 0.0,
    ) -> None:
        if not str(tip_frame):
            raise ValueError("tip_frame must name a frame of the URDF, got ''")
        arm = urdf_model(urdf, str(tip_frame), joint_names)
        add_payload(arm.model, arm.frame_id, payload_kg)
        self.payload_kg = float(payload_kg)
        self.tip_frame = str(tip_frame)
        #: per-joint effort limits from the URDF's <limit effort=...> (0 where none)
        self.effort_limits = arm.effort_limits
        #: per-joint position limits (rad or m; -inf, inf where none) and speed limits (0: none)
        self.position_limits = arm.position_limits
        self.velocity_limits = arm.velocity_limits
        super().__init__(
            arm.model,
            arm.frame_id,
            arm.joint_names,
            arm.S,
            gravity=gravity,
            viscous=arm.damping if viscous is None else viscous,
            coulomb=arm.friction if coulomb is None else coulomb,
            coulomb_speed=arm.coulomb_speed if coulomb_speed is None else coulomb_speed,
            armature=arm.armature if armature is None else armature,
        )

    def __repr__(self) -> str:
        return (
            f"UrdfModel(tip_frame={self.tip_frame!r}, joint_names={list(self.joint_names)}, "
            f"gravity={self.gravity_enabled}, payload_kg={self.payload_kg})"
        )


@dataclass(frozen=True)
class UrdfSettings:
    """URDF model settings a node takes (ROS conventions: ``robot_description``, ...).

    ``robot_description`` (URDF text) wins over ``urdf_path``; ``joint_names`` empty (or ``['']``)
    means the chain to ``tip_frame``.
    """

    robot_description: str = field(
        default="",
        metadata=param(description="URDF XML of the arm (model: urdf); wins over urdf_path"),
    )
    urdf_path: str = field(
        default="", metadata=param(description="path of the arm's URDF file (model: urdf)")
    )
    tip_frame: str = field(
        default="", metadata=param(description="URDF frame whose origin is the end-effector point")
    )
    # a list default: a tuple default would fix the array's length in the parameter table
    joint_names: list[str] | tuple[str, ...] = field(
        default_factory=lambda: [""],
        metadata=param(
            description="joints used, in order; [''] = the chain from the root to tip_frame"
        ),
    )

    def model(self, options: UrdfOptions | None = None) -> UrdfModel:
        """The ``UrdfModel`` these settings name (``ValueError`` when incomplete or invalid)."""
        opts = options or UrdfOptions()
        source = self.robot_description or self.urdf_path
        if not source:
            raise ValueError("model urdf needs robot_description (URDF text) or urdf_path")
        if not self.tip_frame:
            raise ValueError("model urdf needs tip_frame (the end-effector frame)")
        names = [n for n in self.joint_names if n]
        return UrdfModel(
            source,
            self.tip_frame,
            names or None,
            gravity=opts.gravity,
            viscous=_friction(opts.viscous_n_m_s_per_rad),
            coulomb=_friction(opts.coulomb_n_m),
            coulomb_speed=_friction(opts.coulomb_speed_rad_per_s),
            armature=_friction(opts.armature_kg_m2),
            payload_kg=opts.payload_kg,
        )


def _friction(values: Sequence[float]) -> float | list[float] | None:
    """None for [] (the URDF's values), the value for one, the list for one per joint (friction,
    its turn, armature)."""
    if not values:
        return None
    return float(values[0]) if len(values) == 1 else [float(v) for v in values]


@dataclass(frozen=True)
class UrdfOptions:
    """Dynamics options of a URDF model (parameter group ``urdf.``)."""

    gravity: bool = field(
        default=True,
        metadata=param(
            description="include gravity in the model (false: an observer that leaves G out)"
        ),
    )
    # list defaults: a tuple default would fix the array's length in the parameter table
    viscous_n_m_s_per_rad: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description=("viscous joint friction, one value or one per joint; [] = the URDF's"),
            unit="N m s/rad",
            bounds=(0.0, 1e3),
            details=(
                "N s/m for a prismatic joint. [] = each joint's <dynamics damping> from the URDF."
            ),
        ),
    )
    coulomb_n_m: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description=("Coulomb joint friction, one value or one per joint; [] = the URDF's"),
            unit="N m",
            bounds=(0.0, 1e3),
            details=(
                "N for a prismatic joint. [] = each joint's <dynamics friction> from the URDF."
            ),
        ),
    )
    coulomb_speed_rad_per_s: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="speed over which Coulomb friction turns, Fc tanh(q'/v_c); 0 = Fc sgn(q')",
            unit="rad/s",
            bounds=(0.0, 10.0),
            details=(
                "m/s for a prismatic joint; one value for every joint or one per joint; [] = each "
                "joint's <haptic_dob:dynamics coulomb_speed> from the URDF (0 where none). An "
                "observer's model (haptic-identify --urdf fits it); a simulated arm smooths by its "
                "own physics step and refuses it."
            ),
        ),
    )
    armature_kg_m2: list[float] | tuple[float, ...] = field(
        default_factory=list,
        metadata=param(
            description="rotor inertia reflected to each joint (armature)",
            details=(
                "Added to the inertia matrix's diagonal (kg for a prismatic joint); one value for "
                "every joint or one per joint; [] = each joint's <haptic_dob:dynamics armature> "
                "from the URDF (0 where none)."
            ),
            unit="kg m^2",
            bounds=(0.0, 1e3),
        ),
    )
    payload_kg: float = field(
        default=0.0,
        metadata=param(
            description="a point mass at tip_frame's origin that the URDF lacks (a handle, a tool)",
            unit="kg",
            bounds=(0.0, 100.0),
        ),
    )
