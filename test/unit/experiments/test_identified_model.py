"""The configuration's observer model is what chapter 4 identifies, not a copy of the plant.

``config/slide_sim.yaml``'s ``slide.*`` block (what the observer and the controller assume) must be
least squares on chapter 4's 2.4 N run, to the digits it states: the command that regenerates it
is ``haptic-experiment --parts ch4`` then ``haptic-identify report/runs/ch4_step_2p4/bag``. The
lockstep graph's bag holds that run's batch samples to the bit (``test_identify_graph``), so the
batch session stands in for the bag here.
"""

from __future__ import annotations

from pathlib import Path

from haptic_dob.identification.one_dof import SlideFit, identify
from haptic_sim.experiments import identification
from haptic_sim.slide.session import SessionConfig

CONFIG = Path(__file__).resolve().parents[3] / "config" / "slide_sim.yaml"


def test_the_configs_observer_model_is_least_squares_on_chapter_4s_bag() -> None:
    fit = identify(identification.identification_record(CONFIG))
    base = SessionConfig.from_yaml(CONFIG)
    m = base.model
    assert identification.stated_model(fit) == (m.mass_kg, m.viscous_n_s_per_m, m.coulomb_n), fit
    # and it is not the plant's truth copied: the plant is another block with other numbers
    d = base.device
    assert (m.mass_kg, m.viscous_n_s_per_m, m.coulomb_n) != (
        d.mass_kg,
        d.viscous_n_s_per_m,
        d.coulomb_n,
    )
    assert identification.model_check([fit], m).passed


def test_the_model_check_names_what_least_squares_found_when_the_config_differs() -> None:
    fit = SlideFit("least_squares", "slide", 0.41927, 1.2733, 0.23922, None, None, None, 49, None)
    stale = SessionConfig.from_yaml(CONFIG).replace(model__mass_kg=0.416)
    check = identification.model_check([fit], stale.model)
    assert not check.passed and "(found (0.4193, 1.273, 0.2392))" in check.text
    assert not identification.model_check(
        [], stale.model
    ).passed  # least squares failed: no model stated
