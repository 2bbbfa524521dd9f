"""Find the configuration files the project installs under ``share/haptic_dob/config``, and the
files they name beside them."""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path
from typing import Any

from ament_index_python.packages import PackageNotFoundError, get_package_share_directory

from haptic_dob.errors import InputError
from haptic_msgs_py.ament import ensure_ament_prefix


def config_dir() -> Path:
    """The installed config directory (``<prefix>/share/haptic_dob/config``)."""
    ensure_ament_prefix()
    try:
        return Path(get_package_share_directory("haptic_dob")) / "config"
    except PackageNotFoundError:  # pragma: no cover - only without an install
        return Path(__file__).resolve().parents[2] / "config"


def resolve_config(name_or_path: str | Path) -> Path:
    """A path that exists, or the installed config of that name (``slide_sim`` or ``.yaml``;
    ``excite/touch`` in a folder of the config directory)."""
    p = Path(name_or_path)
    if p.is_file():
        return p
    name = p.name if p.suffix in (".yaml", ".yml") else f"{p.name}.yaml"
    inside = [] if p.is_absolute() else [config_dir() / p.parent / name]
    for candidate in (*inside, config_dir() / name):
        if candidate.is_file():
            return candidate
    if p.exists():
        raise InputError(f"{p} is not a file")
    available = ", ".join(sorted(f.stem for f in config_dir().glob("*.yaml")))
    raise InputError(f"no config {str(name_or_path)!r}; a path or one of: {available}")


def urdf_beside(sections: Mapping[str, dict[str, Any]], config: str | Path) -> None:
    """Take a relative ``urdf_path`` of any section from the config's own directory where the
    file is there, in place (the installed configs name ``urdf/arm7.urdf``,
    ``urdf/phantom_omni.urdf`` beside them); else it stays relative to the working directory."""
    here = Path(config).resolve().parent
    for values in sections.values():
        given = values.get("urdf_path")
        relative = isinstance(given, str) and given and not Path(given).is_absolute()
        if relative and (here / str(given)).is_file():
            values["urdf_path"] = str(here / str(given))
