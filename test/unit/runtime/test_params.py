"""Declarative parameter tables: specs from dataclasses, checks with reasons, round trips."""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import pytest

from haptic_dob.core.control import ImpedanceLaw
from haptic_dob.core.environment import VirtualWall
from haptic_dob.runtime.params import ParamSpec, build, param, specs_of, values_of
from haptic_sim.hand import HandParams


def test_specs_carry_description_unit_range_and_choices() -> None:
    specs = {s.name: s for s in specs_of(ImpedanceLaw)}
    assert specs["mode"].choices == ("OL", "CL", "DOB") and specs["mode"].default == "OL"
    assert specs["kf"].min == 0.0 and specs["kf"].kind is float
    assert "[N]" in specs["max_force_n"].full_description()
    wall = {s.name: s for s in specs_of(VirtualWall, "wall.")}
    assert wall["wall.normal"].default == [1.0, 0.0, 0.0] and wall["wall.normal"].kind is list
    assert wall["wall.normal"].length == 3
    assert specs_of(HandParams, read_only=True)[0].read_only


@pytest.mark.parametrize(
    ("spec", "value", "reason"),
    [
        (ParamSpec("kf", 0.0, "gain", min=0.0), -1.0, "kf must be >= 0"),
        (ParamSpec("kf", 0.0, "gain", max=10.0), 11, "kf must be <= 10"),
        (ParamSpec("kf", 0.0, "gain"), "x", "kf must be a number"),
        (ParamSpec("kf", 0.0, "gain"), float("nan"), "kf must be finite"),
        (ParamSpec("kf", 0.0, "gain"), True, "kf must be a number"),
        (ParamSpec("n", 1, "count"), 1.5, "n must be an integer"),
        (ParamSpec("m", "OL", "mode", choices=("OL", "CL")), "X", "m must be one of OL, CL"),
        (ParamSpec("v", [0.0, 0.0], "vec", length=2), [1.0], "v must have 2 elements"),
        (ParamSpec("v", [0.0, 0.0], "vec"), [1.0, float("inf")], "finite numbers"),
        (ParamSpec("s", ["a"], "names"), ["a", 1], "s must be an array of strings"),
        (ParamSpec("b", False, "flag"), 1, "b must be a bool"),
    ],
)
def test_refused_values_come_with_a_reason(spec: ParamSpec, value, reason: str) -> None:
    assert reason in spec.check(value)


def test_accepted_values_have_no_reason() -> None:
    assert ParamSpec("kf", 0.0, "gain", min=0.0).check(3) is None
    assert ParamSpec("v", [0.0, 0.0], "vec").check([1, 2.5]) is None
    assert ParamSpec("s", ["a"], "names").check(["a", "b", "c"]) is None


def test_build_and_values_round_trip() -> None:
    wall = VirtualWall(1600.0, 2.0, (0.0, 0.0, -0.01), (0.0, 0.0, -1.0))
    values = values_of(wall, "wall.")
    assert values["wall.position"] == [0.0, 0.0, -0.01]
    assert build(VirtualWall, values, "wall.") == wall
    assert build(ImpedanceLaw, {"mode": "DOB", "kf": 25}) == ImpedanceLaw("DOB", 25.0)


def test_a_range_declared_for_an_array_holds_for_each_element() -> None:
    from haptic_dob.core.models.urdf import UrdfOptions

    (spec,) = [s for s in specs_of(UrdfOptions, "urdf.") if s.name == "urdf.coulomb_n_m"]
    assert spec.check([0.1, 0.2]) is None
    assert spec.check([0.1, -0.2]) == "urdf.coulomb_n_m must be >= 0 N m, got -0.2"
    assert spec.check([2000.0]) == "urdf.coulomb_n_m must be <= 1000 N m, got 2000"


@dataclass(frozen=True)
class _Group:
    """A settings group as the nodes declare one."""

    gain: float = field(
        default=1.0,
        metadata=param(
            description="a gain", unit="N/m", bounds=(0.0, 10.0), details="Only the docs say so."
        ),
    )
    floor: float = field(default=0.0, metadata=param(description="a floor", bounds=(-1.0, None)))
    mode: str = field(
        default="a", metadata=param(description="a mode", choices=("a", "b"), read_only=True)
    )
    cpus: list[int] | tuple[int, ...] = field(
        default_factory=list, metadata=param(description="CPUs")
    )
    names: list[str] | tuple[str, ...] = field(
        default_factory=list, metadata=param(description="names")
    )
    scale: list[float] | tuple[float, ...] = field(
        default_factory=list, metadata=param(description="scales")
    )


def test_param_is_keyword_only() -> None:
    old_form: Any = param  # the old positional form, out of the converter's and mypy's sight
    with pytest.raises(TypeError):
        old_form("a gain", "N/m", 0.0, 10.0)


def test_a_row_carries_bounds_details_and_its_one_line_description() -> None:
    gain, floor, mode, *_ = specs_of(_Group, "g.")
    assert (gain.name, gain.min, gain.max, gain.unit) == ("g.gain", 0.0, 10.0, "N/m")
    assert gain.details == "Only the docs say so."
    assert gain.full_description() == "a gain [N/m]"  # what ros2 param describe shows
    assert (floor.min, floor.max) == (-1.0, None)
    assert floor.check(-2.0) == "g.floor must be >= -1, got -2"
    assert mode.read_only and mode.full_description() == "a mode one of: a, b"


def test_an_empty_array_takes_its_element_type_from_the_annotation() -> None:
    rows = {s.name: s for s in specs_of(_Group)}
    assert rows["cpus"].item_kind is int
    assert rows["names"].item_kind is str
    assert rows["scale"].item_kind is float


def test_a_node_overrides_a_groups_default_and_heads_its_descriptions() -> None:
    rows = specs_of(_Group, "x.", defaults={"mode": "b"}, about="the other use")
    assert [s.default for s in rows[:3]] == [1.0, 0.0, "b"]
    assert rows[0].description == "the other use: a gain"
    assert specs_of(_Group)[2].default == "a"  # the dataclass keeps its own default
    with pytest.raises(TypeError, match="no parameter nope"):
        specs_of(_Group, defaults={"nope": 1})
