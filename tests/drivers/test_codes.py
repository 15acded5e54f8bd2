"""One table of codes: every stored code variable's CF attributes, the kernels' plain
integers and the schema page all come from ``stabdae._codes``."""

from __future__ import annotations

import warnings

import numpy as np
import pytest

import stabdae
from conftest import pendulum_scene
from stabdae import _codes, _measures
from stabdae._schema import _CODE_VARIABLES, SCHEMA, schema_markdown
from stabdae.engine import decay, rhs

FAMILIES = [_codes.Status, _codes.BetaReason, _codes.FitKind, _codes.StabilityClass,
            _codes.TauStarReason, _codes.ProbeStage, _codes.LawKind, _codes.DecisionReason,
            _codes.ProfileReason]  # fmt: skip


@pytest.mark.parametrize("family", FAMILIES, ids=lambda f: f.__name__)
def test_each_family_is_dense_with_distinct_messages(family):
    values = [int(c) for c in family]
    assert values == list(range(len(values)))
    messages = [c.message for c in family]
    assert all(messages) and len(set(messages)) == len(messages)
    words = [c.flag_meaning for c in family]
    assert all(words) and len(set(words)) == len(words)  # CF: one word per flag value
    assert all(w.replace("_", "").isalnum() for w in words), words


@pytest.mark.parametrize(("variable", "family"), _CODE_VARIABLES)
def test_stored_code_variables_take_their_flags_from_the_table(variable, family):
    attrs = SCHEMA[variable][3]
    assert attrs["flag_values"] == [int(c) for c in family]
    assert attrs["flag_meanings"].split() == [c.flag_meaning for c in family]
    page = schema_markdown()
    for c in family:
        assert f"| {int(c)} | `{c.name}` |" in page


def test_the_kernels_integers_are_the_tables():
    assert [decay.R_FITTED, decay.R_NO_TRANSIENT, decay.R_STOPPED, decay.R_NOT_DECAYING] == [
        int(_codes.BetaReason[n]) for n in ("FITTED", "NO_TRANSIENT", "STOPPED", "NOT_DECAYING")]
    assert decay.K_MAP == int(_codes.FitKind.MAP) and decay.K_NONE == int(_codes.FitKind.NONE)
    assert decay.REASONS == {int(c): c.message for c in _codes.BetaReason}
    assert (rhs.LAW_CONSTANT, rhs.LAW_THEOREM5, rhs.LAW_USER, rhs.LAW_ACPR,
            rhs.LAW_SCALAR_BLOCKS) == tuple(int(c) for c in _codes.LawKind)  # fmt: skip
    assert _measures.CLASSES == tuple(c.message for c in _codes.StabilityClass)
    assert _measures.GROWING == int(_codes.StabilityClass.GROWING)
    assert stabdae.Status is _codes.Status


def test_a_stored_code_reads_back_as_its_message():
    """What an ensemble stores decodes through the table: each member's status and β
    reason name what happened to it."""
    model = pendulum_scene()  # the scene most tests use: its kernels are compiled already
    x0 = np.tile(model.reference_state(), (3, 1))
    x0[1, 0] += 0.3
    x0[2] = np.nan  # not finite: stops at once
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = stabdae.ensemble(model, stabdae.baumgarte(10.0, 1.0), "midpoint", 1e-2, 3.0,
                              x0=x0)  # fmt: skip
    status = [_codes.Status(int(s)) for s in ds.status.values]
    assert status[:2] == [_codes.Status.OK] * 2 and status[2] != _codes.Status.OK
    reasons = [_codes.BetaReason(int(r)).message for r in ds.beta_reason.values]
    assert reasons[1] == "fitted" and reasons[2] == "stopped", reasons
    meanings = ds.status.attrs["flag_meanings"].split()
    assert meanings[int(ds.status.values[2])] == status[2].name.lower()
