"""The documentation's code runs: every ```python block of the getting-started page, and
the xarray recipe of the studies page on a small study's dataset.  (The site itself is
built with ``mkdocs build --strict`` in CI; see README.md.)"""

from __future__ import annotations

import re
from pathlib import Path

import numpy as np
import pytest

from conftest import study_file
from stabdae.study.run import run_study
from stabdae.study.spec import load_study

ROOT = Path(__file__).resolve().parents[2]
DOCS = ROOT / "docs"


def python_blocks(page: str, after: str | None = None) -> list[str]:
    text = (DOCS / page).read_text(encoding="utf-8")
    if after is not None:
        text = text[text.index(after) :]
    return re.findall(r"```python\n(.*?)```", text, flags=re.S)


def test_getting_started_runs(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    blocks = python_blocks("getting-started.md")
    assert len(blocks) == 3
    namespace: dict = {}
    for block in blocks:
        exec(compile(block, "getting-started.md", "exec"), namespace)
    # what the page says the numbers show
    ens, ds = namespace["ens"], namespace["ds"]
    assert float(ens.fraction_bounded) == 1.0
    assert abs(float(ens.beta_median) / float(ens.beta_theory_discrete) - 1.0) < 0.02
    assert 1e-6 < float(ens.residual_floor.median()) < 1e-5
    norms = ds.residual_norm.values
    assert norms[20] < 1e-2 * norms[0] and 1e-6 < norms[-1] < 1e-5  # decayed to the floor
    # the numbers the page quotes, read from the page
    page = (DOCS / "getting-started.md").read_text()
    quoted = re.search(r"fall from (\S+) to (\S+) and (\S+), then stay near (\S+):", page)
    for value, text in zip(norms[[0, 10, 20, 40]], quoted.groups()):
        digits = len(text.split("e")[0].replace(".", ""))  # as many digits as quoted
        assert f"{value:.{digits - 1}e}".replace("e-0", "e-") == text, (value, text)
    about = re.search(r"# about ([\d.]+) and ([\d.]+)", page).groups()
    assert f"{float(ens.beta_median):.3g}" == about[0], (float(ens.beta_median), about)
    floor = re.search(r"the truncation floor, about (\S+)", page).group(1)
    assert f"{float(ens.residual_floor.median()):.0e}".replace("e-0", "e-") == floor
    assert (tmp_path / "pendulum_ensemble.nc").is_file()


def test_xarray_recipe_runs(tmp_path, monkeypatch):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    out = run_study(load_study(study_file(tmp_path, members=16)), progress=False)
    (block,) = python_blocks("studies.md", after="## Reading the dataset with xarray")
    block = block.replace("results/pendulum_tau_omega.nc", str(out))
    namespace: dict = {}
    exec(compile(block, "studies.md", "exec"), namespace)
    assert namespace["ok"].dims == ("tau",)
    assert namespace["ratio"].dims == ("tau", "omega")
    ds = namespace["ds"]
    # what the recipe says it computes, cell by cell from the raw arrays
    fb, rho = ds.fraction_stable.values, ds.spectral_radius.values
    cells = [(fb[i, j] == 1) == (rho[i, j] < 1) for i in range(fb.shape[0])
             for j in range(fb.shape[1])]  # fmt: skip
    assert float(namespace["agree"]) == sum(cells) / len(cells)
    kept = (ds.fraction_stable > 0).values
    assert kept.any() and np.all(np.isfinite(namespace["worst"].values[kept]))
    ds.close()


def test_docs_and_code_speak_of_the_project_alone():
    """What users read names no internal planning files, issues or work sessions."""
    pattern = re.compile(r"shared/|DESIGN §|\bCONTRACT\b|(?i:\bissue \d|\bsession \d)")
    paths = [ROOT / "README.md", ROOT / "studies" / "README.md", *(ROOT / "docs").glob("*.md"),
             *(ROOT / "src").rglob("*.py"), *(ROOT / "kernels").rglob("*.py")]  # fmt: skip
    found = [f"{p.relative_to(ROOT)}:{i}: {line.strip()}" for p in paths
             for i, line in enumerate(p.read_text().splitlines(), 1) if pattern.search(line)]
    assert not found, "\n".join(found)
