"""The recorder's parameters and the bag it creates."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from haptic_dob.bag.write import open_writer
from haptic_dob.recorder.settings import (
    DEFAULT_TOPICS,
    LOG_TIMES,
    STORAGES,
    new_bag_path,
    progress_topic,
    recorder_specs,
)


def test_parameters() -> None:
    specs = {s.name: s for s in recorder_specs()}
    assert list(specs) == [
        "output",
        "storage",
        "log_time",
        "topics",
        "namespaces",
        "duration_s",
        "rate_hz",
        "progress_rate_hz",
        "snapshot_timeout_s",
        "drain_timeout_s",
    ]
    assert specs["storage"].choices == STORAGES
    assert specs["log_time"].choices == LOG_TIMES and specs["log_time"].default == "session"
    assert specs["topics"].default == DEFAULT_TOPICS and specs["topics"].length is None
    assert [n for n, s in specs.items() if not s.read_only] == ["rate_hz"]
    assert specs["namespaces"].default == [""]  # its own


def test_progress_goes_to_the_own_namespace_or_each_given_one() -> None:
    assert progress_topic("") == "recorder/progress"  # relative: the recorder's namespace
    assert progress_topic("/master") == progress_topic("/master/") == "/master/recorder/progress"


def test_every_storage_opens(tmp_path: Path) -> None:
    for storage in STORAGES:
        writer = open_writer(tmp_path / storage, storage)
        writer.close()
        assert (tmp_path / storage / "metadata.yaml").exists()


def test_the_bag_is_new_and_named(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert new_bag_path(str(tmp_path / "bag")) == tmp_path / "bag"
    monkeypatch.chdir(tmp_path)
    assert re.fullmatch(r"haptic_\d{8}_\d{6}", str(new_bag_path("")))
    (tmp_path / "bag").mkdir()
    with pytest.raises(ValueError) as err:
        new_bag_path("bag")
    assert str(err.value) == "bag exists already; the recorder never overwrites a bag"
