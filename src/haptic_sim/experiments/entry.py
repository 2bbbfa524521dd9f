"""What one entry of the reproduction's table (``parts.EXPERIMENTS``) says: how its part runs
(``GraphJob`` through the node graph, ``BatchJob`` in batch), its figures, and its section of the
report (``Experiment``).
"""

from __future__ import annotations

from collections.abc import Callable
from concurrent.futures import Executor
from dataclasses import dataclass
from pathlib import Path
from typing import Generic, TypeVar

from haptic_sim.experiments.graph_runs import GraphRun
from haptic_sim.experiments.records import Check, ExperimentResults, RunAnalysis
from haptic_sim.slide.session import SessionConfig

R = TypeVar("R")


@dataclass(frozen=True)
class GraphJob(Generic[R]):
    """A part run through the node graph: its runs, and its result from their analyses."""

    runs: Callable[[Path, int, bool], list[GraphRun]]  # (base config file, seed, quick)
    collect: Callable[[list[RunAnalysis], SessionConfig], R]  # the runs' analyses, in order
    analyse: bool = True  # False: the part reads its bags itself (no haptic-analyze figures)


@dataclass(frozen=True)
class BatchJob(Generic[R]):
    """A part run in batch simulation (its result cached in ``batch/<part>.json``)."""

    compute: Callable[[SessionConfig, Executor, Path], R]  # (base, process pool, figures dir)
    done: Callable[[R], str]  # the progress line once it is done


@dataclass(frozen=True)
class Figure(Generic[R]):
    """``figures/<file>`` of a part's section.

    ``plot`` draws it from the result when the report is written; ``simulate`` draws it from a
    simulation of its own while the part runs (when missing); with neither, the part's run
    draws it.
    """

    file: str
    alt: str
    plot: Callable[[R, Path, SessionConfig], None] | None = None
    simulate: Callable[[SessionConfig, Path], None] | None = None


def _nothing(_result: object) -> list[str]:
    return []


def _no_checks(_result: object) -> list[Check]:
    return []


@dataclass(frozen=True)
class Experiment(Generic[R]):
    """One part of the reproduction: how it runs and its section of the report."""

    part: str  # its name in --parts and results.json
    result_type: type[R]
    job: GraphJob[R] | BatchJob[R]
    heading: str
    body: Callable[[R, SessionConfig], list[str]]  # tables and text before the figures
    figures: tuple[Figure[R], ...]
    intro: str = ""
    quick: bool = False  # run by --quick
    notes: Callable[[R], list[str]] = _nothing  # after the figures
    checks: Callable[[R], list[Check]] = _no_checks
    differences: Callable[[R], list[str]] = _nothing  # bullet paragraphs
    console: Callable[[R], list[str]] = _nothing

    def result_in(self, res: ExperimentResults) -> R | None:
        """This part's result in ``res``; None if it was not run."""
        r = res.results.get(self.part)
        return r if isinstance(r, self.result_type) else None
