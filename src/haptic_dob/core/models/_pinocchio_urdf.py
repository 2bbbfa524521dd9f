"""URDF arms for pinocchio: parse, choose the joints, lock the rest (pinocchio's API stays here).

- revolute and prismatic joints: one coordinate each; fixed joints: merged into their links;
  meshes: never read;
- continuous joints (pinocchio's ``RUB``, configuration ``(cos, sin)``): one coordinate, the
  angle as a joint state carries it (``PinocchioModel`` maps it with ``pinocchio.integrate``);
- mimic joints: pinocchio's own, following their master, never coordinates of their own (they
  move with their master when it is chosen, else they are locked with it);
- floating, planar and other multi-DOF joints: refused with the joint's name when they would be
  a coordinate (left out of ``joint_names`` they are locked);
- ``<dynamics damping friction>``: joint friction; a joint's armature and Coulomb turn in its
  ``<haptic_dob:dynamics armature=".." coulomb_speed=".."/>`` (``URDF_NAMESPACE``).

Joints not chosen are locked at their neutral position (zero angle or offset); docs/models.md.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pinocchio as pin

_MIMIC = "JointModelMimic"
_MULTI_DOF = {"JointModelFreeFlyer": "floating", "JointModelPlanar": "planar"}
_FT = pin.FrameType
_FRAME_PREFERENCE = (_FT.BODY, _FT.OP_FRAME, _FT.FIXED_JOINT, _FT.JOINT, _FT.SENSOR)
#: the XML namespace of what the suite adds to a URDF (``xmlns:haptic_dob="..."`` on <robot>)
URDF_NAMESPACE = "urn:haptic-dob:urdf"
#: the element of a <joint> holding its armature and Coulomb turn (attributes, SI units)
EXTRA_DYNAMICS = f"{{{URDF_NAMESPACE}}}dynamics"


@dataclass(frozen=True)
class UrdfArm:
    """A URDF arm reduced to its chosen joints (what ``urdf_model`` returns)."""

    model: pin.Model
    frame_id: int
    joint_names: tuple[str, ...]  # the DeviceModel's joint order
    S: np.ndarray | None  # pinocchio velocity order from ours (a permutation), None = same
    effort_limits: tuple[float, ...]  # from the URDF's <limit effort>, N m or N (0 = none)
    damping: tuple[float, ...]  # <dynamics damping>: viscous friction, N m s/rad or N s/m
    friction: tuple[float, ...]  # <dynamics friction>: Coulomb friction, N m or N
    armature: tuple[float, ...] = ()  # <haptic_dob:dynamics armature>: kg m^2 or kg (0 = none)
    coulomb_speed: tuple[float, ...] = ()  # <haptic_dob:dynamics coulomb_speed>: rad/s or m/s
    # <limit lower upper>: rad or m (-inf, inf for a continuous joint); <limit velocity> (0: none)
    position_limits: tuple[tuple[float, float], ...] = ()
    velocity_limits: tuple[float, ...] = ()


def read_urdf(urdf: str | Path) -> str:
    """The URDF XML: ``urdf`` itself when it is XML text, else the file it names."""
    text = str(urdf)
    if text.lstrip().startswith("<"):
        return text
    path = Path(text).expanduser()
    if not path.is_file():
        raise ValueError(f"urdf: no such file {text!r} (and not URDF XML text)")
    return path.read_text(encoding="utf-8")


def _masters(model: pin.Model) -> dict[str, str]:
    """Mimic joint name -> the joint it follows (the coordinate joint sharing its velocity slot)."""
    coords = {
        model.joints[i].idx_v: model.names[i]
        for i in range(1, model.njoints)
        if model.joints[i].shortname() != _MIMIC and model.joints[i].nv == 1
    }
    return {
        model.names[i]: coords[model.joints[i].idx_v]
        for i in range(1, model.njoints)
        if model.joints[i].shortname() == _MIMIC
    }


def frame_id(model: pin.Model, name: str) -> int:
    """The id of frame ``name``: the link's (body) frame where a joint shares its name."""
    for kind in _FRAME_PREFERENCE:
        if model.existFrame(name, kind):
            return int(model.getFrameId(name, kind))
    raise ValueError(f"frame {name!r} is not a frame of the model")


def _check_coordinate(model: pin.Model, name: str, chosen: bool) -> None:
    """Refuse a joint that cannot be one coordinate (naming it and what to do)."""
    jm = model.joints[model.getJointId(name)]
    if jm.nv == 1 and jm.nq in (1, 2):  # revolute, prismatic, continuous
        return
    kind = _MULTI_DOF.get(jm.shortname(), jm.shortname())
    how = "leave it out of joint_names" if chosen else "name the joints to use in joint_names"
    raise ValueError(
        f"joint {name} is a {kind} joint ({jm.nv} DOF): only revolute, continuous and prismatic "
        f"joints can be coordinates; {how} to lock it"
    )


def _chosen_joints(
    full: pin.Model, tip_frame: str, joint_names: Sequence[str] | None, masters: dict[str, str]
) -> list[str]:
    """The coordinates in our order: ``joint_names`` checked, or the chain to ``tip_frame``."""
    movable = [full.names[i] for i in range(1, full.njoints) if full.names[i] not in masters]
    if joint_names:
        wanted = [str(n) for n in joint_names]
        mimics = [f"{n} (it follows {masters[n]})" for n in wanted if n in masters]
        if mimics:
            raise ValueError(f"joint_names: {', '.join(mimics)} is a mimic joint; name its master")
        unknown = [n for n in wanted if n not in movable]
        if unknown:
            raise ValueError(
                f"joint_names: {', '.join(unknown)} not movable joints of the URDF "
                f"(it has: {', '.join(movable)})"
            )
        if len(set(wanted)) != len(wanted):
            raise ValueError(f"joint_names lists a joint twice: {wanted}")
    else:
        tip_parent = full.frames[frame_id(full, tip_frame)].parentJoint
        chain = [full.names[i] for i in full.supports[tip_parent] if i != 0]
        wanted = list(dict.fromkeys(masters.get(n, n) for n in chain))
        if not wanted:
            raise ValueError(f"tip_frame {tip_frame!r} is not moved by any joint")
    for n in wanted:
        _check_coordinate(full, n, bool(joint_names))
    return wanted


def urdf_model(
    urdf: str | Path, tip_frame: str, joint_names: Sequence[str] | None = None
) -> UrdfArm:
    """Parse a URDF (string or path) and keep ``joint_names`` (default: the chain to the tip).

    Every other joint is locked at its neutral position; mimic joints follow their master.
    Raises ``ValueError`` with one clear line for a bad URDF, an unknown tip frame or joint, or a
    joint that cannot be a coordinate (naming it).
    """
    xml = read_urdf(urdf)
    try:
        full = pin.buildModelFromXML(xml, True)  # True: mimic joints follow their masters
    except (RuntimeError, ValueError) as exc:
        raise ValueError(f"urdf: cannot parse the URDF: {exc}") from None
    if not full.existFrame(tip_frame):
        names = ", ".join(f.name for f in full.frames if f.name != "universe")
        raise ValueError(f"tip_frame {tip_frame!r} is not a frame of the URDF (it has: {names})")
    masters = _masters(full)
    wanted = _chosen_joints(full, tip_frame, joint_names, masters)
    keep = set(wanted) | {m for m, master in masters.items() if master in wanted}
    lock = [i for i in range(1, full.njoints) if full.names[i] not in keep]
    model = pin.buildReducedModel(full, lock, pin.neutral(full)) if lock else full
    idx_v = [model.joints[model.getJointId(n)].idx_v for n in wanted]
    S = None
    if idx_v != list(range(len(idx_v))):
        S = np.zeros((len(idx_v), len(idx_v)))
        for ours, theirs in enumerate(idx_v):
            S[theirs, ours] = 1.0
    limits = tuple(float(model.effortLimit[i]) for i in idx_v)
    limits = tuple(v if math.isfinite(v) and v > 0.0 else 0.0 for v in limits)
    damping = tuple(float(model.damping[i]) for i in idx_v)
    friction = tuple(float(model.friction[i]) for i in idx_v)
    extra = extra_dynamics(xml)
    armature = tuple(extra.get(n, {}).get("armature", 0.0) for n in wanted)
    speed = tuple(extra.get(n, {}).get("coulomb_speed", 0.0) for n in wanted)
    fid = frame_id(model, tip_frame)
    ranges = tuple(_range(model, n) for n in wanted)
    speeds = tuple(_finite(float(model.velocityLimit[i])) for i in idx_v)
    return UrdfArm(
        model, fid, tuple(wanted), S, limits, damping, friction, armature, speed, ranges, speeds
    )


def _finite(value: float) -> float:
    return value if math.isfinite(value) and value > 0.0 else 0.0


def _range(model: pin.Model, name: str) -> tuple[float, float]:
    """A joint's position limits; (-inf, inf) for a continuous joint (configuration (cos, sin))."""
    jm = model.joints[model.getJointId(name)]
    if jm.nq != 1:
        return (-math.inf, math.inf)
    lo, hi = float(model.lowerPositionLimit[jm.idx_q]), float(model.upperPositionLimit[jm.idx_q])
    return (lo, hi) if lo < hi else (-math.inf, math.inf)


def extra_dynamics(xml: str) -> dict[str, dict[str, float]]:
    """Joint name -> the attributes of its ``<haptic_dob:dynamics>`` (armature, coulomb_speed),
    each finite and >= 0; ``ValueError`` naming the joint otherwise."""
    if URDF_NAMESPACE not in xml:
        return {}
    out: dict[str, dict[str, float]] = {}
    for joint in ET.fromstring(xml).findall("joint"):
        element = joint.find(EXTRA_DYNAMICS)
        if element is None:
            continue
        name = joint.get("name", "")
        values = {}
        for key in ("armature", "coulomb_speed"):
            text = element.get(key)
            if text is None:
                continue
            try:
                value = float(text)
            except ValueError:
                value = math.nan
            if not (math.isfinite(value) and value >= 0.0):
                raise ValueError(f"urdf: joint {name}: {key} must be a number >= 0, got {text!r}")
            values[key] = value
        out[name] = values
    return out


def add_payload(model: pin.Model, frame: int, mass_kg: float) -> None:
    """Put a point mass of ``mass_kg`` (kg, >= 0) at frame ``frame``'s origin, on the body that
    carries it (a handle, a tool, a sensor the URDF does not have). Before any ``Data``."""
    if not (math.isfinite(mass_kg) and mass_kg >= 0.0):
        raise ValueError(f"payload_kg must be finite and >= 0, got {mass_kg!r}")
    if mass_kg == 0.0:
        return
    f = model.frames[frame]
    point = pin.Inertia(float(mass_kg), f.placement.translation.copy(), np.zeros((3, 3)))
    model.appendBodyToJoint(f.parentJoint, point, pin.SE3.Identity())
