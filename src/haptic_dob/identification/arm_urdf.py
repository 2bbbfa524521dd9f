"""A URDF's links' inertials and joints' dynamics, read and written back (ElementTree).

``link_inertials`` reads every link's ``<inertial>`` as a mass (kg), a centre of mass and the
inertia about it (kg m^2), both in the link frame's axes (the ``<origin rpy>`` applied).
``rewrite_urdf`` returns the XML with the given links' ``<inertial>`` replaced (origin at the
centre of mass, ``rpy`` zero) and the given joints' ``<dynamics damping friction>`` set, their
armature and Coulomb turn in ``<haptic_dob:dynamics>`` (``haptic_dob.core.models.urdf``); every
other element, attribute and comment is kept (the XML's layout is not), and a comment says where
the values came from.
"""

from __future__ import annotations

import io
import math
import re
import xml.etree.ElementTree as ET
from collections.abc import Mapping
from dataclasses import dataclass

import numpy as np
from numpy.typing import NDArray

from haptic_dob.core.models._pinocchio_urdf import EXTRA_DYNAMICS, URDF_NAMESPACE, read_urdf

Arr = NDArray[np.float64]
_INERTIA = ("ixx", "ixy", "ixz", "iyy", "iyz", "izz")


@dataclass(frozen=True)
class LinkInertial:
    """A link's mass (kg), centre of mass (m, (3,)) and inertia about it (kg m^2, (3, 3)), in the
    link frame's axes."""

    mass: float
    com: Arr
    inertia: Arr


@dataclass(frozen=True)
class JointDynamics:
    """A joint's viscous (N m s/rad) and Coulomb (N m) friction, the speed its Coulomb friction
    turns over (rad/s, 0: a sign) and its armature (kg m^2); N, m/s and kg for a prismatic one."""

    damping: float
    friction: float
    coulomb_speed: float = 0.0
    armature: float = 0.0


def rpy_matrix(rpy: Arr) -> Arr:
    """The rotation of a URDF ``rpy`` (fixed axes x, then y, then z)."""
    r, p, y = (float(a) for a in rpy)
    cr, sr, cp, sp, cy, sy = (
        math.cos(r),
        math.sin(r),
        math.cos(p),
        math.sin(p),
        math.cos(y),
        math.sin(y),
    )
    rz = np.array([[cy, -sy, 0.0], [sy, cy, 0.0], [0.0, 0.0, 1.0]])
    ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    out: Arr = rz @ ry @ rx
    return out


def _floats(text: str | None, n: int, where: str) -> Arr:
    values = (text or " ".join(["0"] * n)).split()
    try:
        out = np.array([float(v) for v in values], dtype=np.float64)
    except ValueError:
        out = np.full(0, math.nan)
    if out.shape != (n,) or not np.all(np.isfinite(out)):
        raise ValueError(f"urdf: {where}: expected {n} numbers, got {text!r}")
    return out


def link_inertials(urdf: str) -> dict[str, LinkInertial]:
    """Every link's inertial (zero for a link without one); ``urdf`` is XML text or a path."""
    root = ET.fromstring(read_urdf(urdf))
    out = {}
    for link in root.findall("link"):
        name = link.get("name", "")
        inertial = link.find("inertial")
        if inertial is None:
            out[name] = LinkInertial(0.0, np.zeros(3), np.zeros((3, 3)))
            continue
        origin = inertial.find("origin")
        xyz = _floats(None if origin is None else origin.get("xyz"), 3, f"link {name} origin")
        rpy = _floats(None if origin is None else origin.get("rpy"), 3, f"link {name} origin")
        mass_el = inertial.find("mass")
        mass = _floats(None if mass_el is None else mass_el.get("value"), 1, f"link {name} mass")
        el = inertial.find("inertia")
        i = {k: 0.0 if el is None else float(el.get(k, "0")) for k in _INERTIA}
        tensor = np.array(
            [
                [i["ixx"], i["ixy"], i["ixz"]],
                [i["ixy"], i["iyy"], i["iyz"]],
                [i["ixz"], i["iyz"], i["izz"]],
            ]
        )
        R = rpy_matrix(rpy)
        out[name] = LinkInertial(float(mass[0]), xyz, R @ tensor @ R.T)
    return out


def _text(x: float) -> str:
    return f"{x:.9g}"


def _set_inertial(link: ET.Element, value: LinkInertial) -> None:
    old = link.find("inertial")
    at = list(link).index(old) if old is not None else 0
    if old is not None:
        link.remove(old)
    new = ET.Element("inertial")
    ET.SubElement(new, "origin", xyz=" ".join(_text(c) for c in value.com), rpy="0 0 0")
    ET.SubElement(new, "mass", value=_text(value.mass))
    tensor = value.inertia
    idx = {"ixx": (0, 0), "ixy": (0, 1), "ixz": (0, 2), "iyy": (1, 1), "iyz": (1, 2), "izz": (2, 2)}
    ET.SubElement(new, "inertia", {k: _text(float(tensor[ij])) for k, ij in idx.items()})
    link.insert(at, new)


def _set_dynamics(joint: ET.Element, value: JointDynamics) -> None:
    dyn = joint.find("dynamics")
    if dyn is None:
        dyn = ET.SubElement(joint, "dynamics")
    dyn.set("damping", _text(value.damping))
    dyn.set("friction", _text(value.friction))
    extra = joint.find(EXTRA_DYNAMICS)
    if extra is None:
        extra = ET.SubElement(joint, EXTRA_DYNAMICS)
    extra.set("armature", _text(value.armature))
    extra.set("coulomb_speed", _text(value.coulomb_speed))


def rewrite_urdf(
    urdf: str,
    inertials: Mapping[str, LinkInertial],
    dynamics: Mapping[str, JointDynamics],
    note: str,
) -> str:
    """``urdf`` (XML text or a path) with those links' inertials and joints' dynamics replaced,
    and ``note`` as a comment at the top of ``<robot>``; ``ValueError`` for an unknown name."""
    xml = read_urdf(urdf)
    for _, (prefix, uri) in ET.iterparse(io.StringIO(xml), events=("start-ns",)):
        if prefix and not re.fullmatch(r"ns\d+", prefix):  # keep the file's prefixes (xacro...)
            ET.register_namespace(prefix, uri)
    ET.register_namespace("haptic_dob", URDF_NAMESPACE)
    root = ET.fromstring(xml, parser=ET.XMLParser(target=ET.TreeBuilder(insert_comments=True)))
    links = {el.get("name", ""): el for el in root.findall("link")}
    joints = {el.get("name", ""): el for el in root.findall("joint")}
    for name, inertial in inertials.items():
        if name not in links:
            raise ValueError(f"urdf: no link {name!r}")
        _set_inertial(links[name], inertial)
    for name, dyn in dynamics.items():
        if name not in joints:
            raise ValueError(f"urdf: no joint {name!r}")
        _set_dynamics(joints[name], dyn)
    root.insert(0, ET.Comment(f" {note.replace('--', '- -')} "))
    ET.indent(root, space="  ")
    prolog = re.sub(r"<\?xml[^>]*\?>", "", xml[: xml.find("<robot")]).strip()  # its comments
    head = '<?xml version="1.0"?>\n' + (prolog + "\n" if prolog else "")
    return head + ET.tostring(root, encoding="unicode") + "\n"
