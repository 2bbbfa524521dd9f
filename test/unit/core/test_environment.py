"""The unilateral virtual wall, 1-D and as a 3-D half-space."""

from __future__ import annotations

import numpy as np
import pytest

from haptic_dob.core.environment import VirtualWall


def test_slide_wall_is_the_thesis_spring() -> None:
    wall = VirtualWall.along_axis(800.0, position_m=0.01)
    assert wall.force((0.009, 0, 0), (0.1, 0, 0)) == (0.0, 0.0, 0.0)
    assert wall.force((0.012, 0, 0), (0.0, 0, 0)) == pytest.approx((-800.0 * 0.002, 0, 0))


def test_damping_adds_and_never_pulls() -> None:
    wall = VirtualWall(1000.0, 10.0, (0, 0, 0), (1, 0, 0))
    assert wall.force((0.001, 0, 0), (0.05, 0, 0)) == pytest.approx((-1.5, 0, 0))
    # leaving fast: K delta + B delta' < 0 would pull; the wall gives zero instead
    assert wall.force((0.001, 0, 0), (-0.5, 0, 0)) == (0.0, 0.0, 0.0)


def test_half_space_in_3d() -> None:
    # floor 0.01 m below the origin, free space above: the normal points down into it
    wall = VirtualWall(1000.0, 0.0, (0.0, 0.0, -0.01), (0.0, 0.0, -1.0))
    assert wall.penetration((0.3, -0.2, -0.012)) == pytest.approx(0.002)
    f = wall.force((0.3, -0.2, -0.012), (0.0, 0.0, 0.0))
    assert f == pytest.approx((0.0, 0.0, 2.0))  # pushes the hand up
    assert wall.force((0.3, -0.2, -0.005), (0.0, 0.0, 0.0)) == (0.0, 0.0, 0.0)


def test_oblique_normal_is_normalised() -> None:
    wall = VirtualWall(100.0, 0.0, (0, 0, 0), (1.0, 1.0, 0.0))
    f = np.array(wall.force((0.01, 0.01, 0.0), (0, 0, 0)))
    n = np.array([1.0, 1.0, 0.0]) / np.sqrt(2)
    np.testing.assert_allclose(f, -100.0 * (0.02 / np.sqrt(2)) * n)


def test_a_huge_normal_is_a_direction_too() -> None:
    """Entries whose squares overflow (a fuzzed parameter found it) still give the unit normal."""
    for normal, unit in (((0.0, 0.0, 1.34e154), (0.0, 0.0, 1.0)), ((-1e308, 0.0, 0.0), (-1, 0, 0))):
        assert VirtualWall(normal=normal).normal == pytest.approx(unit)


@pytest.mark.parametrize(
    ("kwargs", "name"),
    [
        ({"stiffness_n_per_m": -1.0}, "stiffness"),
        ({"damping_n_s_per_m": np.nan}, "damping"),
        ({"normal": (0.0, 0.0, 0.0)}, "normal"),
        ({"position": (0.0, 1.0)}, "position"),
    ],
)
def test_wall_rejects_bad_settings(kwargs: dict, name: str) -> None:
    with pytest.raises(ValueError, match=name):
        VirtualWall(**kwargs)


def test_checked_force_rejects_bad_state() -> None:
    with pytest.raises(ValueError, match=r"^p "):
        VirtualWall().force_checked((np.nan, 0, 0), (0, 0, 0))
    with pytest.raises(ValueError, match=r"^v "):
        VirtualWall().force_checked((0, 0, 0), (0, 0))
