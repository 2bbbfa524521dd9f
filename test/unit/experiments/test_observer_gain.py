"""The observer gain per Kf: chapter 5.3's accuracy, capped below the chatter limit of each Kf."""

from __future__ import annotations

import pytest

from haptic_sim.experiments import observer_gain
from haptic_sim.slide.session import SessionConfig
from support.paths import ROOT

CONFIG = ROOT / "config" / "slide_sim.yaml"


@pytest.fixture(scope="module")
def base() -> SessionConfig:
    return SessionConfig.from_yaml(CONFIG)


def test_the_accuracy_gain_is_the_best_of_5_3s_sessions(base: SessionConfig) -> None:
    """``ACCURACY_GAIN`` is what ``best_gain`` finds for the configuration (batch: the two OL
    sessions once, the observer replayed per gain), and it is a minimum: a gain a fifth slower
    or faster estimates the force sensor's reading worse."""
    gain, err = observer_gain.best_gain(base)
    assert gain == observer_gain.ACCURACY_GAIN
    records = [observer_gain.run_session(observer_gain.session(base, w)) for w in (0.0, 800.0)]
    for other in (0.8 * gain, 1.2 * gain):
        assert observer_gain.replay_error(base, records, other) > err


def test_the_gain_per_kf_is_capped_below_the_chatter_limit(base: SessionConfig) -> None:
    """Kf = 1 and 2 keep the accuracy gain (their chatter limits are far above it); Kf = 25 and
    100 take the largest whole gain below theirs (30.8 and 7.7 N s/m with the amplifier lag):
    30 and 7, the configuration's node default at Kf = 100."""
    c = observer_gain.ACCURACY_GAIN
    assert observer_gain.gain_at(1.0, base) == c
    assert observer_gain.gain_at(2.0, base) == c
    g25, limit25 = observer_gain.gain_for(25.0, c, base)
    assert limit25 is not None and g25 == 30.0 and g25 < limit25 < g25 + 1.0
    g100, limit100 = observer_gain.gain_for(100.0, c, base)
    assert limit100 is not None and g100 == 7.0 and g100 < limit100 < g100 + 1.0
    assert g100 == base.observer.gain
    # a slower accuracy gain is never raised to the limit
    assert observer_gain.gain_for(25.0, 12.0, base)[0] == 12.0
