"""Study files: validation before anything compiles, grids, and ``stabdae theory``."""

from __future__ import annotations

import textwrap
from pathlib import Path

import numpy as np
import pytest
import xarray as xr

import stabdae
from stabdae.study.cli import main
from stabdae.study.spec import StudyError, load_study

BASE = """
[model]
file = "pendulum"

[law]
kind = "baumgarte"
omega = 10.0
xi = 1.0

[scheme]
name = "rk2"

[run]
t_end = 1.0
tau = 1e-3
save_dt = 0.05

[ensemble]
members = 16
radius = [1e-6, 1e-3]
seed = 1
"""


def write(tmp_path, text, name="study.toml"):
    path = tmp_path / name
    path.write_text(textwrap.dedent(text))
    return path


def test_a_valid_study_and_its_grid(tmp_path):
    path = write(tmp_path, BASE + """
[sweep]
tau = [1e-3, 2e-3, 5e-3]
omega = [5.0, 10.0]
"g" = [9.81, 1.62]
""")  # fmt: skip
    study = load_study(path)
    assert list(study.axes) == ["run.tau", "law.omega", "model.g"]
    assert study.shape == (3, 2, 2) and study.size == 12
    idx, values = list(study.points())[-1]
    assert idx == (2, 1, 1) and values == {"run.tau": 5e-3, "law.omega": 10.0, "model.g": 1.62}
    s = study.setup(values)
    assert s["tau"] == 5e-3 and s["params"]["g"] == 1.62
    assert s["law"].A(study.model)[0, 0] == -100.0


def test_tau_sweep_snaps_onto_the_sample_grid(tmp_path):
    path = write(tmp_path, BASE + "\n[sweep]\ntau = { logspace = [1e-4, 1e-1, 7] }\n")
    study = load_study(path)
    taus = study.axes["run.tau"]
    save_dt = 0.05
    for asked, got in zip(np.geomspace(1e-4, 1e-1, 7), taus):
        if asked <= save_dt:
            assert got <= asked and save_dt / got == pytest.approx(round(save_dt / got))
        else:
            assert got / save_dt == pytest.approx(round(got / save_dt)) and got <= asked
    assert study.setup({"run.tau": taus[-1]})["stride"] == 2  # τ = 0.1 spans 2 samples


@pytest.mark.parametrize(
    "edit, message",
    [
        # unknown keys and sections
        (("[run]", "[run]\nstep = 3"), r"\[run\] step: unknown key; known: t_end, tau"),
        (("[scheme]", "[schemes]"), r"\[schemes\]: unknown section"),
        (("xi = 1.0", "xi = 1.0\nL = [[1.0]]"), r"\[law\] L: not a parameter of the 'baumgarte'"),
        (("xi = 1.0", "xi = 1.0\nk = 3.0"), r"\[law\] k: model 'pendulum' has no nonholonomic"),
        # wrong types
        (("tau = 1e-3", 'tau = "small"'), r"\[run\] tau: must be a number, got str 'small'"),
        (("members = 16", "members = 16.5"), r"\[ensemble\] members: must be an integer"),
        (("seed = 1", "seed = true"), r"\[ensemble\] seed: must be an integer, got bool"),
        (("seed = 1", "seed = 1\nstates = 1"),
         r"\[ensemble\] states: must be true or false, got int 1"),
        # impossible values
        (("tau = 1e-3", "tau = -1e-3"), r"\[run\] tau: must be positive and finite, got -0.001"),
        (("radius = [1e-6, 1e-3]", "radius = [1e-3, 1e-6]"),
         r"\[ensemble\] radius: needs 0 < low <= high"),
        (("members = 16", "members = 0"), r"\[ensemble\] members: must be at least 1, got 0"),
        (("omega = 10.0", "omega = 0.0"), r"\[law\] omega: must be positive, got 0.0"),
        (("tau = 1e-3", "tau = 3e-3"), r"at the base point: .*must be a whole multiple"),
        (("kind = \"baumgarte\"", "kind = \"magic\""), r"\[law\] kind: unknown law 'magic'"),
        (("name = \"rk2\"", "name = \"rk7\""), r"\[scheme\] name: unknown scheme 'rk7'"),
        (('file = "pendulum"', 'file = "nowhere.py"'), r"\[model\] file: no such model file"),
        (('file = "pendulum"', 'file = "pendulum"\nparams = { G = 1.0 }'),
         r"\[model\] params.G: model 'pendulum' has no parameter 'G'; its parameters: g, l"),
        (("t_end = 1.0\n", ""), r"\[run\] t_end: missing \(required\)"),
    ],
)
def test_validation_names_the_file_and_key(tmp_path, edit, message):
    old, new = edit
    assert old in BASE
    path = write(tmp_path, BASE.replace(old, new, 1))
    with pytest.raises(StudyError, match=r"^study.toml: " + message):
        load_study(path)


@pytest.mark.parametrize(
    "sweep, message",
    [
        ("speed = [1.0]", r"\[sweep\] speed: not a sweepable parameter; sweepable here: tau"),
        ("omega = []", r"\[sweep\] omega: must be a non-empty array of numbers"),
        ("omega = [1.0, -2.0]", r"\[sweep\] omega: values must be positive"),
        ("omega = { logspace = [0.0, 1.0, 3] }", r"logspace needs positive ends"),
        ("omega = { range = [1, 2] }", r"must be an array or \{ linspace"),
        ("omega = { linspace = [1.0, 2.0, 2.5] }", r"needs \[start, stop, count\]"),
        ('"A[0,0]" = [1.0]', r"matrix entries can only be swept with \[law\] kind = 'matrix'"),
        ("tau = [1e-3, 1.01e-3]", r"land on repeated step sizes"),
    ],
)
def test_sweep_validation(tmp_path, sweep, message):
    path = write(tmp_path, BASE + "\n[sweep]\n" + sweep + "\n")
    with pytest.raises(StudyError, match=message):
        load_study(path)


def test_ambiguous_sweep_name_asks_for_a_prefix(tmp_path):
    text = BASE.replace('file = "pendulum"', 'file = "chaplygin_sleigh"').replace(
        'kind = "baumgarte"\nomega = 10.0\nxi = 1.0', 'kind = "theorem5"\nk = 2.0'
    )
    # the sleigh has no parameter k, so "k" is the law's gain; "m" is the sleigh's mass
    study = load_study(write(tmp_path, text + "\n[sweep]\nk = [1.0, 2.0]\nm = [1.0, 2.0]\n"))
    assert list(study.axes) == ["law.k", "model.m"]


def test_matrix_law_entries_sweep(tmp_path):
    text = BASE.replace('kind = "baumgarte"\nomega = 10.0\nxi = 1.0',
                        'kind = "matrix"\nA = [[-100.0, -20.0]]')  # fmt: skip
    study = load_study(write(tmp_path, text + '\n[sweep]\n"A[0,1]" = [-20.0, -5.0]\n'))
    law = study.setup({"law.A[0,1]": -5.0})["law"]
    np.testing.assert_array_equal(law.A(study.model), [[-100.0, -5.0]])
    bad = write(tmp_path, text + '\n[sweep]\n"A[3,0]" = [1.0]\n', "bad.toml")
    with pytest.raises(StudyError, match=r"at law.A\[3,0\] = 1: index 3 is out of bounds"):
        load_study(bad)


def test_theory_command_prints_the_table(tmp_path, capsys):
    path = write(tmp_path, BASE + "\n[sweep]\ntau = [0.01, 0.05]\n")
    assert main(["theory", str(path)]) == 0
    out = capsys.readouterr().out
    assert "Theorem 3: eigenvalues of Ã: -10" in out
    assert "largest tau for midpoint: spectral 0.2, max_norm 0, two_norm 0" in out
    rows = [line.split() for line in out.splitlines() if line.strip().startswith(("0.01", "0.05"))]
    assert len(rows) == 2 and all(r[4] == "yes" for r in rows)
    # the numbers behind the table: midpoint at critical damping, τ limit exactly 2/ω
    from stabdae.study.theory import for_study

    ds = for_study(load_study(path))
    assert ds.tau_limit_spectral.values == pytest.approx([0.2, 0.2], rel=1e-9)
    assert (ds.tau_limit_spectral.values < 0.2).all()
    assert (ds.tau_limit_max_norm.values == 0).all() and (ds.tau_limit_two_norm.values == 0).all()


def test_cli_reports_study_errors(tmp_path, capsys):
    path = write(tmp_path, BASE.replace("tau = 1e-3", "tau = -1.0"))
    assert main(["theory", str(path)]) == 2
    assert "study.toml: [run] tau: must be positive" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["midpoint", "heun", "rk4", "euler"])
def test_two_stage_sweep_with_a_fixed_scheme_is_refused(tmp_path, name):
    """Sweeping a (or sigma) under a scheme without parameters was ignored silently (every
    grid point the same); it is an error naming the key."""
    text = BASE.replace('name = "rk2"', f'name = "{name}"') + "\n[sweep]\na = [0.5, 1.0]\n"
    with pytest.raises(StudyError, match=rf"at scheme\.a = 0\.5: scheme '{name}' has no "
                                         r"parameters, got \['a'\]"):  # fmt: skip
        load_study(write(tmp_path, text))


@pytest.mark.parametrize("name", ["rk2", "two_stage"])
def test_two_stage_sweep_changes_the_scheme_per_point(tmp_path, name):
    text = BASE.replace('name = "rk2"', f'name = "{name}"') + "\n[sweep]\na = [0.5, 0.25]\n"
    text = text.replace("[scheme]\n", "[scheme]\nsigma = 2.0\n") if name == "two_stage" else text
    study = load_study(write(tmp_path, text))
    schemes = [study.setup(v)["scheme"] for _, v in study.points()]
    assert [sc.params["a"] for sc in schemes] == [0.5, 0.25]
    assert schemes[0].b.tolist() != schemes[1].b.tolist() or schemes[0].A.tolist() != \
        schemes[1].A.tolist()


def test_states_are_stored_when_the_study_asks(tmp_path):
    from stabdae.study.run import run_point

    for text, stored in ((BASE, False), (BASE + "states = true\n", True)):
        study = load_study(write(tmp_path, text))
        ds = run_point(study, dict(study.points())[()]).to_dataset()
        assert ("x0" in ds and "x_final" in ds) is stored and ds.sizes["member"] == 16


@pytest.mark.parametrize(
    "edit, message",
    [
        (('file = "pendulum"', 'file = "pendulum"\nparams = { g = nan }'),
         r"\[model\] params.g: must be finite"),
        (("seed = 1", "seed = -1"), r"\[ensemble\] seed: must be a non-negative integer"),
        (("seed = 1", "seed = 1\nblock = 1000000"),
         r"\[ensemble\] block: block = 1000000 needs .* MiB of thread stack"),
        (("seed = 1", "seed = 1\n[sweep]\ntau = { linspace = [1e-3, 1e-2, 1000000000] }"),
         r"\[sweep\] tau: linspace of 1000000000 values: at most 100000 per axis"),
        (("seed = 1", "seed = 1\n[sweep]\ntau = { logspace = [1e-4, 1e-2, 2000] }\n"
                      "omega = { linspace = [1, 100, 2000] }"),
         r"\[sweep\]: 4e\+06 grid points: at most 1000000"),
    ],
)
def test_study_file_values_refused_before_anything_runs(tmp_path, edit, message):
    """NaN parameters, a negative seed, a block that cannot fit the thread stack, grids too
    large to run: errors naming the key, before anything compiles."""
    text = BASE.replace(*edit)
    assert text != BASE
    with pytest.raises(StudyError, match=message):
        load_study(write(tmp_path, text))


@pytest.mark.parametrize("path", ["/tmp/elsewhere.nc", "../up.nc"])
def test_output_outside_the_study_folder_is_refused_unless_replaced(tmp_path, path,
                                                                    monkeypatch):  # fmt: skip
    """A study file writes beneath its folder or the current one: another ``[output] path``
    is refused where it would be used, naming the key, and an output given by the caller
    (``stabdae run -o``) replaces it."""
    from stabdae.study.run import output_path

    for sub in ("study", "cwd"):
        (tmp_path / sub).mkdir()
    monkeypatch.chdir(tmp_path / "cwd")
    text = BASE.replace("seed = 1", f'seed = 1\n[output]\npath = "{path}"')
    study = load_study(write(tmp_path / "study", text))
    with pytest.raises(StudyError, match=r"\[output\] path: must lie beneath the study's "
                                         r"folder or the current one"):  # fmt: skip
        output_path(study)
    assert output_path(study, tmp_path / "mine.nc") == tmp_path / "mine.nc"
    inside = load_study(write(tmp_path / "study", BASE.replace(
        "seed = 1", 'seed = 1\n[output]\npath = "out/x.nc"'), "inside.toml"))  # fmt: skip
    assert output_path(inside) == tmp_path / "study" / "out" / "x.nc"
    # a link inside the study's folder that leads out of it is not followed silently
    (tmp_path / "away").mkdir()
    (tmp_path / "study" / "results").symlink_to(tmp_path / "away")
    linked = load_study(write(tmp_path / "study", BASE.replace(
        "seed = 1", 'seed = 1\n[output]\npath = "results/x.nc"'), "linked.toml"))  # fmt: skip
    with pytest.raises(StudyError, match=r"got 'results/x.nc', which a link leads to "
                                         r".*away/x.nc"):  # fmt: skip
        output_path(linked)


def test_a_tableau_in_the_study_file(tmp_path):
    """[scheme] with A, b, c and order: the user's own scheme (here Kutta's third order,
    written out), checked against the order conditions and recorded in the dataset."""
    tableau = 'A = [[0, 0, 0], [0.5, 0, 0], [-1, 2, 0]]\nb = [0.16666666666666666, ' \
              '0.6666666666666666, 0.16666666666666666]\nc = [0, 0.5, 1]\norder = 3\n'
    text = BASE.replace('name = "rk2"', 'name = "my_kutta"\n' + tableau)
    scheme = load_study(write(tmp_path, text)).setup()["scheme"]
    assert scheme.name == "my_kutta" and scheme.order == 3
    np.testing.assert_array_equal(scheme.b, stabdae.rk3().b)
    assert "scheme_b" in scheme.attrs()
    wrong = text.replace("order = 3", "order = 4")
    with pytest.raises(StudyError, match=r"\[scheme\] name: .*declared order 4"):
        load_study(write(tmp_path, wrong, "wrong.toml"))
    # a and sigma belong to the two-stage family: beside a tableau, given or swept, they
    # would change nothing
    with pytest.raises(StudyError, match=r"\[scheme\].*a tableau is its A, b and c: 'a' "):
        load_study(write(tmp_path, text.replace("order = 3", "order = 3\na = 0.3"), "a.toml"))
    with pytest.raises(StudyError, match=r"a tableau is its A, b and c: 'sigma' "):
        load_study(write(tmp_path, text + "\n[sweep]\nsigma = [1.0, 2.0]\n", "s.toml"))
    # a tableau named like a built-in scheme would be recorded (and its theory computed) as
    # that scheme
    with pytest.raises(StudyError, match=r"'rk4' is the name of a built-in scheme"):
        load_study(write(tmp_path, text.replace('"my_kutta"', '"RK4"'), "rk4.toml"))
    posing = stabdae.Scheme("rk4", scheme.A, scheme.b, scheme.c, 3, {})
    np.testing.assert_array_equal(posing.attrs()["scheme_b"], stabdae.rk3().b)
    assert "scheme_b" not in stabdae.rk4().attrs()


def test_moved_tau_values_are_reported(tmp_path, capsys):
    """A swept τ that does not fit the sample grid is moved onto it, and the study says so
    (printed by stabdae theory and stabdae run)."""
    path = write(tmp_path, BASE + "\n[sweep]\ntau = [0.3, 0.0846, 0.01]\n")
    study = load_study(path)
    assert study.axes["run.tau"].tolist() == pytest.approx([0.25, 0.05, 0.01], rel=1e-12)
    assert "0.3 → 0.25" in study.describe() and "0.0846 → 0.05" in study.describe()
    assert "0.01 →" not in study.describe()
    assert main(["theory", str(path)]) == 0
    out = capsys.readouterr().out
    assert "swept tau moved onto the sample grid" in out and "cond whether |R|P < 1" in out
    rec = stabdae.theory.recommend_gain("rk2", load_study(path).setup()["tau"])
    assert f"Baumgarte omega = {rec['omega']:.6g}, xi = 0.707107" in out
    assert "the residual is gone after 1 step" in out


@pytest.mark.parametrize("name", sorted(p.name for p in (Path(__file__).resolve().parents[2]
                                                        / "studies").glob("*.toml")))  # fmt: skip
def test_shipped_studies_load_from_the_repository_root(name, monkeypatch):
    """The study files the README and docs run validate as they are run (from the
    repository's root: their output goes to results/ there)."""
    root = Path(__file__).resolve().parents[2]
    monkeypatch.chdir(root)
    study = load_study(root / "studies" / name)
    assert study.output == root / "results" / name.replace(".toml", ".nc")



def test_shipped_theorem5_study_runs_with_more_members_than_traces(monkeypatch):
    """The shipped Theorem 5 study as written (256 members, 64 stored traces): its grid
    point runs, and the bound is judged on the stored traces, one flag per trace."""
    from stabdae.study.run import run_point

    root = Path(__file__).resolve().parents[2]
    monkeypatch.chdir(root)
    study = load_study(root / "studies" / "sleigh_theorem5_tau_k.toml")
    *_, (_, values) = study.points()  # the largest step: the cheapest point
    ds = run_point(study, values).to_dataset()
    assert ds.sizes["member"] == study.ensemble["members"] > ds.sizes["trace"] > 0
    for which in ("proven", "printed"):
        held = ds[f"bound_{which}_held"]
        assert held.dims == ("trace",) and set(np.unique(held.values)) <= {0, 1}



def test_a_study_runs_model_code_only_from_its_own_folder(tmp_path, capsys):
    """A study file is data and a model file is code: a model outside the study's folder
    (by path or through a link inside it) is refused, naming the path and the option; a
    model below the folder, a built-in scene, and --trust-model are accepted."""
    pend = (Path(__file__).resolve().parents[2] / "kernels" / "pendulum.py").read_text()
    elsewhere = tmp_path / "elsewhere"
    elsewhere.mkdir()
    (elsewhere / "pend_far.py").write_text(pend)
    home = tmp_path / "home"
    (home / "models").mkdir(parents=True)
    (home / "models" / "pend_near.py").write_text(pend)
    (home / "pend_link.py").symlink_to(elsewhere / "pend_far.py")
    far = write(home, BASE.replace('file = "pendulum"', 'file = "../elsewhere/pend_far.py"'))
    with pytest.raises(StudyError, match=r"\[model\] file: \.\./elsewhere/pend_far\.py lies "
                                         r"outside the study's folder .*--trust-model"):
        load_study(far)
    link = write(home, BASE.replace('file = "pendulum"', 'file = "pend_link.py"'), "l.toml")
    with pytest.raises(StudyError, match=r"outside the study's folder .*through a link"):
        load_study(link)
    assert main(["theory", str(far)]) == 2
    assert "--trust-model" in capsys.readouterr().err
    assert load_study(far, trust_model=True).model.name == "pendulum"
    assert main(["theory", str(far), "--trust-model"]) == 0
    near = write(home, BASE.replace('file = "pendulum"', 'file = "models/pend_near.py"'),
                 "n.toml")  # fmt: skip
    assert load_study(near).model.name == "pendulum"



def test_a_step_larger_than_save_dt_keeps_the_sample_grid(tmp_path):
    """τ > save_dt: the note states the spacing the dataset really has (save_dt, a step
    every few samples); a τ that is not a whole multiple of save_dt would put the samples
    off that grid, and is refused with the nearest ones that fit."""
    study = load_study(write(tmp_path, BASE.replace("tau = 1e-3", "tau = 0.1")))
    assert "samples every 0.05, one in 2 on a step, the others NaN" in study.describe()
    assert study.setup()["stride"] == 2
    with pytest.raises(StudyError, match=r"\[run\] tau: 0.125 is larger than save_dt = 0.05 "
                                         r"and not a whole multiple .*nearest: 0.1 or 0.15"):
        load_study(write(tmp_path, BASE.replace("tau = 1e-3", "tau = 0.125"), "b.toml"))


SEARCH = """
[model]
file = "pendulum"

[law]
kind = "baumgarte"
omega = 10.0
xi = 1.0

[scheme]
name = "rk4"

[run]
epsilon = 1.0

[ensemble]
members = 16
radius = [1e-8, 1e-3]
seed = 1

[search]
tau = { bisect = [1e-3, 3.0], rtol = 0.05 }
search_members = 8
steps = 2000

[sweep]
omega = [10.0, 100.0]
"""


def test_search_study_finds_the_boundary_per_point_and_plots_it(tmp_path):
    """A [search] study: one boundary per value of the other axes, equal to
    stabdae.boundary at that point; the summary and picture follow."""
    from stabdae.plots import plot_dataset
    from stabdae.study.run import run_study

    path = write(tmp_path, SEARCH)
    study = load_study(path)
    assert study.search["tau"] == (1e-3, 3.0) and "searched: tau" in study.describe()
    lines = []
    out = run_study(study, tmp_path / "b.nc", progress=False, log=lines.append)
    ds = xr.open_dataset(out).load()
    assert ds.tau_star.dims == ("omega",) and ds.probe_tau.dims == ("omega", "probe")
    one = stabdae.boundary(study.model, stabdae.baumgarte(100.0, 1.0), "rk4",
                           tau=(1e-3, 3.0), rtol=0.05, members=16, search_members=8,
                           steps=2000, radius=(1e-8, 1e-3), seed=1, epsilon=1.0)  # fmt: skip
    assert float(ds.tau_star.sel(omega=100.0)) == float(one.tau_star)
    assert (ds.tau_star < ds.tau_limit_spectral).all()
    assert "tau_spectral" in lines[-2]
    pictures = plot_dataset(out, tmp_path / "pic")
    assert [p.name for p in pictures] == ["pic_boundary.png"] and pictures[0].stat().st_size


def test_a_theorem5_search_study_has_no_path_theory(tmp_path):
    """A [search] study of a state-dependent law (Theorem 5 on the sleigh): one boundary
    per value of the other axis; the conditions along the reference path belong to a
    grid of steps and are not computed for a searched step (they are, per τ, in a swept
    study of the same law)."""
    from stabdae.study.run import run_study

    text = (SEARCH.replace('file = "pendulum"', 'file = "chaplygin_sleigh"')
            .replace('kind = "baumgarte"\nomega = 10.0\nxi = 1.0', 'kind = "theorem5"\nk = 4.0')
            .replace("members = 16", "members = 8").replace("search_members = 8",
                                                            "search_members = 4")
            .replace("steps = 2000", "steps = 100").replace("rtol = 0.05", "rtol = 0.3")
            .replace("omega = [10.0, 100.0]", "k = [4.0]"))  # fmt: skip
    out = run_study(load_study(write(tmp_path, text)), tmp_path / "s.nc", progress=False,
                    log=lambda line: None)  # fmt: skip
    ds = xr.open_dataset(out).load()
    assert ds.tau_star.dims == ("k",) and np.isfinite(ds.tau_star_low).all()
    assert not [v for v in ds.data_vars if v.startswith("path_")]


@pytest.mark.parametrize("edit, message", [
    (("steps = 2000", "steps = 2000\nt_end = 2.0"), r"\[search\] t_end: give steps or t_end"),
    (("bisect = [1e-3, 3.0]", "bisect = [3.0, 1e-3]"), r"\[search\] tau.bisect: needs 0 < low"),
    (("rtol = 0.05", "rtol = 5.0"), r"\[search\] tau.rtol: must lie in"),
    (("omega = [10.0, 100.0]", "tau = [0.1, 0.2]"), r"\[sweep\] tau: is searched"),
    (("search_members = 8", "search_members = 8\nq = 1.0"), r"\[search\] q:"),
    (("search_members = 8", "search_members = 8\nconfidence = 0.95"),
     r"\[search\] confidence: needs q above 0"),
    (("search_members = 8", "search_members = 8\nq = 0.05\nconfidence = 1.5"),
     r"\[search\] confidence: must lie between 0 and 1"),
    (("members = 16", "members = { max = 64 }"),
     r"\[ensemble\] members: a boundary search runs its probes with a number of members"),
    (("members = 16", "members = { max = 64, batch = 4 }"),
     r"\[ensemble\] members: a boundary search"),
])  # fmt: skip
def test_search_validation(tmp_path, edit, message):
    path = write(tmp_path, SEARCH.replace(*edit))
    with pytest.raises(StudyError, match=r"^study.toml: " + message):
        load_study(path)


def test_summary_names_unstable_members_where_the_law_is_stable():
    """The run's summary has an ``unstable`` column, and below the table a line for each
    grid point whose law is stable in the linear theory (ρ(R) < 1) but has unstable
    members, with their count and reasons; none for a point with ρ ≥ 1 or no unstable
    member."""
    from stabdae._codes import Verdict, VerdictReason
    from stabdae.study.report import summary

    S, U = int(Verdict.STABLE), int(Verdict.UNSTABLE)
    verdict = np.array([[S, S, S, S], [U, U, U, S], [U, U, U, U]], dtype=np.int8)
    reason = np.array([[0, 0, 0, 0], [int(VerdictReason.BLEW_UP), int(VerdictReason.BLEW_UP),
                        int(VerdictReason.BEYOND_BOUND), 0], [int(VerdictReason.GREW)] * 4],
                      dtype=np.int8)  # fmt: skip
    ds = xr.Dataset({"verdict": (("run.tau", "member"), verdict),
                     "verdict_reason": (("run.tau", "member"), reason),
                     "spectral_radius": ("run.tau", [0.5, 0.8, 1.2]),
                     "fraction_stable": ("run.tau", (verdict == S).mean(axis=1)),
                     "fraction_unstable": ("run.tau", (verdict == U).mean(axis=1))},
                    coords={"run.tau": [0.01, 0.02, 0.04]})  # fmt: skip
    text = summary(ds)
    assert "unstable" in text.splitlines()[2]
    notes = text.split("unstable where the law's linear part is stable")[1].splitlines()[1:]
    assert [n for n in notes if n.strip()] == [
        "  tau = 0.02: rho(R) = 0.8 < 1, yet 3 of 4 members unstable (2 blew up; 1 grew "
        "beyond the law's bound)"]
    calm = ds.isel({"run.tau": [0, 2]})
    assert "linear part is stable" not in summary(calm)


def test_summary_gives_delta_star_as_censored_with_its_bracket():
    """δ* in the summary: its value with the bracket where the sample brackets it, a
    censored ``> low`` where every decided member was stable, ``< high`` where none was
    below the smallest unstable, ``none`` without a decided member."""
    from stabdae._codes import RadiusReason
    from stabdae.study.report import summary

    nan = np.nan
    ds = xr.Dataset({"fraction_stable": ("run.tau", [0.5, 1.0, 0.0, nan]),
                     "stability_radius": ("run.tau", [2e-4, nan, nan, nan]),
                     "stability_radius_low": ("run.tau", [1e-4, 1e-3, nan, nan]),
                     "stability_radius_high": ("run.tau", [4e-4, nan, 1e-8, nan]),
                     "stability_radius_reason": ("run.tau", np.array(
                         [int(r) for r in (RadiusReason.BRACKETED, RadiusReason.ABOVE_SAMPLE,
                                           RadiusReason.BELOW_SAMPLE, RadiusReason.NO_MEMBER)],
                         dtype=np.int8))},
                    coords={"run.tau": [0.01, 0.02, 0.04, 0.08]})  # fmt: skip
    rows = summary(ds).strip().splitlines()[1:]
    assert rows[0].split()[-1] == "delta*"
    cells = [r.split("  ")[-1].strip() for r in rows[1:5]]
    assert cells == ["0.0002 [0.0001, 0.0004]", "> 0.001", "< 1e-08", "none"]


def test_summary_lists_each_undecided_point_with_its_reasons():
    """Below the table, a line per grid point whose decision is undecided: its decision
    reason and its undecided members' verdict reasons, the most frequent first (ties by
    code), over the members it ran; none for a decided point, and no section where every
    point is decided."""
    from stabdae._codes import DecisionReason, Status, Verdict, VerdictReason
    from stabdae.study.report import summary

    S, U, D = int(Verdict.STABLE), int(Verdict.UNSTABLE), int(Verdict.UNDECIDED)
    T, A, N = (int(VerdictReason.TOO_SHORT), int(VerdictReason.ABOVE_BOUND),
               int(VerdictReason.NOT_RUN))  # fmt: skip
    verdict = np.array([[S, S, S, S, S], [D, D, D, S, D], [D, U, U, U, D]], dtype=np.int8)
    reason = np.array([[0] * 5, [A, T, A, 0, N], [T, 0, 0, 0, T]], dtype=np.int8)
    status = np.zeros((3, 5), dtype=np.int8)
    status[1, 4] = int(Status.NOT_NEEDED)  # not run: left out of the counts
    decision = np.array([S, D, D], dtype=np.int8)
    why = np.array([int(DecisionReason.STABLE), int(DecisionReason.MEMBERS_UNDECIDED),
                    int(DecisionReason.MAX_REACHED)], dtype=np.int8)  # fmt: skip
    ds = xr.Dataset({"verdict": (("run.tau", "member"), verdict),
                     "verdict_reason": (("run.tau", "member"), reason),
                     "status": (("run.tau", "member"), status),
                     "decision": ("run.tau", decision), "decision_reason": ("run.tau", why),
                     "fraction_stable": ("run.tau", (verdict == S).mean(axis=1))},
                    coords={"run.tau": [0.01, 0.02, 0.04]})  # fmt: skip
    text = summary(ds)
    notes = text.split("undecided grid points")[1].splitlines()[1:]
    assert [n for n in notes if n.strip()] == [
        "  tau = 0.02: members undecided (3 of 4 members undecided: 2 above the law's "
        "bound but not growing (rho < 1); 1 too short)",
        "  tau = 0.04: max members reached (2 of 5 members undecided: 2 too short)"]
    assert "undecided grid points" not in summary(ds.isel({"run.tau": [0]}))


def test_summary_says_which_blown_up_members_met_a_singular_constraint_matrix():
    """Members that blew up are counted by how they stopped; where some stopped at a
    singular S (the constraints lost rank: the theorems assume they do not), the note
    says so instead of blaming only the scheme's remainder."""
    from stabdae._codes import Status, Verdict, VerdictReason
    from stabdae.study.report import summary

    S, U = int(Verdict.STABLE), int(Verdict.UNSTABLE)
    B = int(VerdictReason.BLEW_UP)
    verdict = np.array([[U, U, U, S], [U, S, S, S]], dtype=np.int8)
    reason = np.array([[B, B, B, 0], [B, 0, 0, 0]], dtype=np.int8)
    status = np.array([[int(Status.SINGULAR_S), int(Status.SINGULAR_S),
                        int(Status.NONFINITE_STATE), 0], [int(Status.DIVERGED), 0, 0, 0]],
                      dtype=np.int8)  # fmt: skip
    ds = xr.Dataset({"verdict": (("run.tau", "member"), verdict),
                     "verdict_reason": (("run.tau", "member"), reason),
                     "status": (("run.tau", "member"), status),
                     "spectral_radius": ("run.tau", [0.5, 0.8]),
                     "fraction_stable": ("run.tau", (verdict == S).mean(axis=1)),
                     "fraction_unstable": ("run.tau", (verdict == U).mean(axis=1))},
                    coords={"run.tau": [0.01, 0.02]})  # fmt: skip
    text = summary(ds)
    head, *notes = text.split("unstable where the law's linear part is stable")[1].splitlines()
    assert [n for n in notes if n.strip()] == [
        "  tau = 0.01: rho(R) = 0.5 < 1, yet 3 of 4 members unstable (3 blew up: 2 singular S, "
        "1 non-finite state)",
        "  tau = 0.02: rho(R) = 0.8 < 1, yet 1 of 4 members unstable (1 blew up: 1 diverged)"]
    assert "singular S" in head and "rank" in head
    calm = ds.isel({"run.tau": [1]})
    assert "rank" not in summary(calm)


def test_a_search_studys_progress_moves_with_its_probes(tmp_path):
    """A boundary search's grid point is counted in the members of the probes it is
    expected to run (the bracket's ends, two beside the spectral limit, the bisection to
    rtol, the confirmation); each probe's line moves the bar by its members, and a point
    done sets the total to what the points need on average (before: the bar stood still through a
    point and jumped by the confirmation's members at its end, and its time left was
    the rest of the run at that pace).  The probe lines are stabdae.boundary's own."""
    import math
    import re

    from stabdae.study.run import _Progress, _work_per_point

    pytest.importorskip("tqdm")
    study = load_study(write(tmp_path, SEARCH))
    halvings = math.ceil(math.log2(math.log(3.0 / 1e-3) / math.log(1.05)))
    work = _work_per_point(study)
    assert work == (4 + halvings) * 8 + 16
    lines = []
    stabdae.boundary(study.model, stabdae.baumgarte(10.0, 1.0), "rk4", tau=(1e-3, 3.0),
                     rtol=0.05, members=16, search_members=8, steps=200, progress=lines.append)
    assert lines
    bar = _Progress(2, 0, work, True)
    seen = []
    for line in lines:
        bar.note(line)
        seen.append(bar._bar.n)
    assert seen[0] == 8 and seen == sorted(seen)
    ran = sum(int(m) for m in re.findall(r" of (\d+) members", " ".join(lines)))
    assert seen[-1] == ran  # the members the probes ran, counted as they report them
    bar.point_done()
    # the other point is expected to need as many as this one did
    assert (bar._bar.n, bar._bar.total) == (ran, 2 * ran)
    bar.note(lines[0])
    assert bar._bar.n == ran + 8
    bar.close()
