"""Tables 7.1 and 7.2 are held out: no parameter of the reproduction is read from them.

The thesis's numbers live in ``haptic_sim.experiments.thesis`` and nowhere else. What chooses a
parameter (the configuration's loading, the hand's depth rule, the observer-gain rule, the plan
of the chapter-6 and chapter-7 runs, the batch sessions of the seeds and of every sweep) must
work with that module unimportable, and give the same parameters as with it; the report's
tables alone (``tables``, ``spread_report``, ``sweeps_report``...) set the measurements beside
the thesis's.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from pathlib import Path

from support.paths import ROOT

THESIS = "haptic_sim.experiments.thesis"
#: the modules that choose or apply a parameter of the reproduction's sessions
CHOOSERS = (
    "haptic_sim.hand",
    "haptic_sim.slide.device",
    "haptic_sim.slide.plant",
    "haptic_sim.slide.session",
    "haptic_sim.slide.stability",
    "haptic_sim.experiments.observer_gain",
    "haptic_sim.experiments.observer_vs_sensor",
    "haptic_sim.experiments.plan",
    "haptic_sim.experiments.graph_runs",
    "haptic_sim.experiments.identification",
    "haptic_sim.experiments.spread",
    "haptic_sim.experiments.sweeps",
)

#: builds every parameter set the reproduction runs from and prints it as JSON; ``BLOCK`` makes
#: the thesis module unimportable first
SCRIPT = """
import json, sys
if BLOCK:
    sys.modules[%(thesis)r] = None  # any import of it now raises ImportError
from pathlib import Path
from haptic_sim.experiments import observer_gain, plan, spread, sweeps
from haptic_sim.hand import depth_reference
from haptic_sim.slide.session import SessionConfig
config = Path(%(config)r)
base = SessionConfig.from_yaml(config)
runs = plan.chapter7_plan(config, 0, False) + plan.chapter6_plan(config, 0, False)
ref = depth_reference(base.hand, tuple(plan.CH7_WALLS), base.model.mass_kg,
                      base.model.viscous_n_s_per_m, base.device.max_force_n)
print(json.dumps({
    "runs": {r.name: r.params for r in runs},
    "gains": {str(kf): observer_gain.gain_at(kf, base) for kf in (1.0, 2.0, 25.0, 100.0)},
    "hand": [ref.offset_m, ref.amplitude_m],
    "seeds": [repr(c.config) for c in spread.cells(base)],
    "sweeps": [repr(s.config(base, m, kf, w, v)) for s in sweeps.SWEEPS for m, kf in s.controllers
               for w in s.walls for v in s.values_for(base, kf)],
    "config": repr(base),
    "thesis_loaded": %(thesis)r in sys.modules and sys.modules[%(thesis)r] is not None,
}, sort_keys=True, default=str))
"""


def _parameters(block: bool) -> dict[str, object]:
    code = f"BLOCK = {block}\n" + SCRIPT % {
        "thesis": THESIS,
        "config": str(ROOT / "config" / "slide_sim.yaml"),
    }
    out = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=300, cwd=ROOT
    )
    assert out.returncode == 0, out.stderr
    result: dict[str, object] = json.loads(out.stdout)
    return result


def test_every_parameter_is_chosen_without_the_thesis_tables() -> None:
    """The plan, the gains, the hand and the configuration come out the same with the thesis
    module blocked (an import of it would fail) as with it importable; and the blocked run
    really ran without it."""
    held_out = _parameters(block=True)
    assert held_out.pop("thesis_loaded") is False
    assert held_out["runs"] and held_out["gains"]
    with_it = _parameters(block=False)
    with_it.pop("thesis_loaded")
    assert held_out == with_it


def _source(module: str) -> Path | None:
    """The file of a project module or package (None: not the project's)."""
    base = ROOT / "src" / Path(*module.split("."))
    for path in (base.with_suffix(".py"), base / "__init__.py"):
        if path.is_file():
            return path
    return None


def _imports(module: str) -> set[str]:
    """The project modules ``module``'s source imports, at any depth of its code (relative
    imports resolved; ``from a import b`` names both ``a`` and ``a.b``)."""
    path = _source(module)
    assert path is not None, module
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found: set[str] = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            found.update(a.name for a in node.names)
        elif isinstance(node, ast.ImportFrom):
            parts = package.split(".")
            root = ".".join(parts[: len(parts) - node.level + 1]) if node.level else ""
            name = ".".join(p for p in (root, node.module or "") if p)
            found.add(name)
            found.update(f"{name}.{a.name}" for a in node.names)
    return {m for m in found if _source(m) is not None}


def test_no_parameter_chooser_imports_the_thesis_module_even_indirectly() -> None:
    """Statically: the modules that choose parameters, and everything they import, never name
    the thesis module."""
    seen: set[str] = set()
    todo = list(CHOOSERS)
    while todo:
        m = todo.pop()
        if m in seen:
            continue
        seen.add(m)
        todo.extend(_imports(m))
    assert THESIS not in seen
    assert "haptic_sim.experiments.plan" in seen  # the walk did walk


def test_the_static_check_would_catch_an_import_of_the_thesis() -> None:
    """The walk finds the thesis module where it is imported (the report's tables)."""
    assert THESIS in _imports("haptic_sim.experiments.tables")
