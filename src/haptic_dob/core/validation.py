"""Argument checks of the numeric core: every failure is a ``ValueError`` naming the argument."""

from __future__ import annotations

import array
import math
from collections.abc import Sequence

import numpy as np
from numpy.typing import ArrayLike, NDArray


def finite_scalar(name: str, value: object) -> float:
    """Return ``value`` as a finite float or raise ``ValueError`` naming ``name``."""
    try:
        x = float(value)  # type: ignore[arg-type]  # any object; refusal below
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a real number, got {value!r}") from None
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    return x


def positive(name: str, value: object) -> float:
    """Return ``value`` as a finite float > 0 or raise ``ValueError``."""
    x = finite_scalar(name, value)
    if x <= 0.0:
        raise ValueError(f"{name} must be > 0, got {x}")
    return x


def nonnegative(name: str, value: object) -> float:
    """Return ``value`` as a finite float >= 0 or raise ``ValueError``."""
    x = finite_scalar(name, value)
    if x < 0.0:
        raise ValueError(f"{name} must be >= 0, got {x}")
    return x


def vector(name: str, value: ArrayLike, size: int) -> NDArray[np.float64]:
    """Return ``value`` as a finite float64 vector of length ``size`` or raise ``ValueError``.

    A scalar is accepted when ``size`` is 1.
    """
    try:
        arr = np.asarray(value, dtype=np.float64)
    except (TypeError, ValueError):
        raise ValueError(f"{name} must be a numeric vector of length {size}") from None
    if arr.ndim == 0 and size == 1:
        arr = arr.reshape(1)
    if arr.shape != (size,):
        raise ValueError(f"{name} must have shape ({size},), got shape {arr.shape}")
    if not np.all(np.isfinite(arr)):
        raise ValueError(f"{name} must be finite, got {arr.tolist()}")
    return arr


def unit_vector(name: str, value: ArrayLike, size: int = 3) -> NDArray[np.float64]:
    """Return ``value`` normalised to unit length; a zero vector raises ``ValueError``."""
    arr = vector(name, value, size)
    with np.errstate(over="ignore"):
        norm = float(np.linalg.norm(arr))
    if norm < 1e-12:
        raise ValueError(f"{name} must be a non-zero vector, got {arr.tolist()}")
    if not np.isfinite(norm):  # finite entries whose squares overflow: scale them first
        scaled: NDArray[np.float64] = arr / float(np.max(np.abs(arr)))
        return scaled / float(np.linalg.norm(scaled))
    return arr / norm


def scalar_of(name: str, value: object) -> float:
    """Return the single finite element of a scalar or length-1 sequence (fast path of the loop)."""
    kind = type(value)
    if kind is float:
        x: float = value  # type: ignore[assignment]  # checked: a float
    elif kind is tuple or kind is list or kind is np.ndarray or kind is array.array:
        if len(value) != 1:  # type: ignore[arg-type]  # a sized kind, checked above
            raise ValueError(f"{name} must be a scalar or a length-1 vector, got {value!r}")
        x = float(value[0])  # type: ignore[index]  # a sized kind, checked above
    elif isinstance(value, (int, np.floating, np.integer)) and not isinstance(value, bool):
        x = float(value)
    elif isinstance(value, Sequence) and not isinstance(value, str) and len(value) == 1:
        x = float(value[0])
    else:
        raise ValueError(f"{name} must be a scalar or a length-1 vector, got {value!r}")
    if not math.isfinite(x):
        raise ValueError(f"{name} must be finite, got {x}")
    return x
