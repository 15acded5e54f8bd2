"""An ensemble warns once for its stopped members, counted by reason."""

from __future__ import annotations

import warnings

import stabdae
from conftest import pendulum_scene


# ---------------------------------------------------------------- the ensemble's summary
def test_ensemble_warns_once_with_the_stopped_members_by_reason():
    """Euler at τω = 2.5 diverges: one warning counts the stopped members by reason."""
    pend = pendulum_scene()
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        ds = stabdae.ensemble(pend, stabdae.baumgarte(100.0), "euler", 0.025, 2.0, members=16,
                              radius=(1e-4, 1e-3))  # fmt: skip
    stopped = [w for w in caught if issubclass(w.category, stabdae.IntegrationWarning)]
    assert len(stopped) == 1
    n = int((ds.status.values != 0).sum())
    assert n == 16
    assert f"16 of 16 members stopped: {n} diverged" in str(stopped[0].message)
    assert stopped[0].filename == __file__  # points at the caller
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a run where every member finishes is silent
        stabdae.ensemble(pend, stabdae.baumgarte(10.0), "midpoint", 0.01, 0.2, members=8)
