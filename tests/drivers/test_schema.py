"""One dataset schema: valid units, history and time format on every dataset kind, and
the schema page generated from it."""

from __future__ import annotations

import stabdae
from conftest import ROOT, assert_schema, load_scene, pendulum_scene
from stabdae import theory
from stabdae._schema import schema_markdown, udunits_ok


# ---------------------------------------------------------------- one schema
def test_udunits_check_accepts_units_and_refuses_prose():
    for good in ("1", "m", "m2", "m2 s-1", "m s-1", "s-1", "rad s-1", "J", "kg m^2",
                 "m/s", "m2 s-2"):  # fmt: skip
        assert udunits_ok(good), good
    for bad in ("", "model units", "mixed (see state_units)", "m2 per s", "meters"):
        assert not udunits_ok(bad), bad


def test_every_dataset_has_valid_units_history_and_one_time_format(tmp_path):
    """Trajectories (fixed and adaptive), ensembles (fixed and adaptive, with Theorem 5's
    columns), the theory over a study's grid and along a path: valid units or
    per-component units, a history, one created_at format; the pendulum's residual in m²
    and its velocity in m s-1."""
    from stabdae.study.spec import load_study
    from stabdae.study.theory import for_study

    pend = pendulum_scene()
    law = stabdae.baumgarte(10.0)
    traj = stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.01)
    assert traj.residual.attrs.get("units_per_component") == "component_units"
    assert list(traj.component_units.values) == ["m2", "m2 s-1"]
    assert traj.attrs["history"].endswith("integrate: one trajectory (stabdae "
                                          f"{stabdae.__version__})")  # fmt: skip
    sleigh = load_scene("chaplygin_sleigh")
    datasets = [
        traj,
        stabdae.integrate_adaptive(pend, None, law, 0.2, rtol=1e-6, save_dt=0.1),
        stabdae.integrate(pend, None, law, "rk4", 0.01, 0.2, 0.1, with_multipliers=True),
        stabdae.ensemble(pend, law, "midpoint", 0.01, 0.2, members=8),
        stabdae.ensemble(pend, law, tau=0.01, t_end=0.2, rtol=1e-6, members=4),
        stabdae.ensemble(sleigh, stabdae.theorem5(2.0), "rk4", 0.01, 0.2, members=4),
        theory.along_path(pend, law, "euler", stabdae.integrate(pend, None, law, "euler",
                                                                0.01, 0.2, 0.01)),  # fmt: skip
    ]
    study = tmp_path / "s.toml"
    study.write_text('[model]\nfile = "pendulum"\n[law]\nkind = "baumgarte"\nomega = 10.0\n'
                     '[run]\nt_end = 0.2\ntau = 0.01\n[sweep]\ntau = [0.01, 0.02]\n')  # fmt: skip
    datasets.append(for_study(load_study(study)))
    for ds in datasets:
        assert_schema(ds)
    ens = datasets[3]
    assert ens.residual_norm.attrs["units_per_component"] == "component_units"
    assert ens.beta.attrs["units"] == "s-1"
    # a model whose constraints share one unit: the norms carry it
    sl = datasets[5]
    assert sl.residual_norm.attrs["units"] == "m s-1" and sl.gamma.attrs["units"] == "m s-1"


def test_schema_page_is_generated_from_the_schema():
    page = (ROOT / "docs" / "schema.md").read_text()
    assert page == schema_markdown(), (
        "docs/schema.md is stale: regenerate it with python -c \"from stabdae._schema import "
        "schema_markdown; open('docs/schema.md', 'w').write(schema_markdown())\""
    )
