"""The checks that guard the project itself can fail: CI's docs build counts warnings, the
docs toolchain is pinned, and the mutation runner never calls a mutant caught when no test
ran, nor when its tests could not run, and writes its results file from a full run."""

from __future__ import annotations

import re
import shlex
import subprocess
import sys
import time

import pytest

from conftest import ROOT

sys.path.insert(0, str(ROOT / "tests" / "mutation"))
from generate import GROUPS, generate  # noqa: E402
from mutants import MUTANTS  # noqa: E402
from run import outcome_of, results_header  # noqa: E402


def _mkdocs_lines(text: str) -> list[list[str]]:
    """The argument lists of every ``mkdocs build`` command in a shell text."""
    out = []
    for line in text.splitlines():
        line = line.split("#", 1)[0]
        if "mkdocs" not in line:
            continue
        for part in re.split(r"&&|;", line):
            words = shlex.split(part)
            if "mkdocs" in words and "build" in words:
                out.append(words[words.index("mkdocs"):])
    return out


def test_ci_docs_build_counts_warnings():
    """``--quiet`` hides the warnings that ``--strict`` counts: with it the check cannot fail."""
    ci = (ROOT / ".ci" / "run").read_text()
    builds = _mkdocs_lines(ci)
    assert builds, ".ci/run builds no docs"
    for words in builds:
        assert "--strict" in words
        assert not {"--quiet", "-q"} & set(words), words


def test_docs_toolchain_is_pinned_where_it_is_installed():
    constraints = ROOT / "docs" / "constraints.txt"
    pins = dict(line.split("==") for line in constraints.read_text().splitlines()
                if line and not line.startswith("#"))  # fmt: skip
    assert {"mkdocs", "mkdocs-material", "mkdocstrings", "mkdocstrings-python"} <= set(pins)
    for text in ((ROOT / ".ci" / "run").read_text(), (ROOT / "README.md").read_text()):
        installs = [line for line in text.splitlines() if "pip install" in line and "docs" in line]
        assert installs and all("-c docs/constraints.txt" in line for line in installs)


@pytest.mark.parametrize(("code", "out", "expected"), [
    (0, "3 passed", "SURVIVED"),
    (1, "FAILED tests/test_x.py::test_a - assert\n1 failed", "caught"),
    (1, "ERROR tests/test_x.py::test_a - fixture failed\n1 error", "caught"),
    (2, "ERROR tests/test_x.py - ImportError\n1 error", "BROKEN"),
    (3, "INTERNALERROR> Traceback", "BROKEN"),
    (4, "ERROR: file or directory not found: tests/test_gone.py", "NOT RUN"),
    (5, "no tests ran in 0.01s", "NOT RUN"),
    (-11, "Fatal Python error: Segmentation fault", "caught (crash)"),
    ("timeout", "", "timeout"),
])  # fmt: skip
def test_mutation_outcomes(code, out, expected):
    outcome, _ = outcome_of(code, out)
    assert outcome.split(" (")[0] == expected.split(" (")[0], outcome
    assert outcome.startswith("caught") == expected.startswith("caught")


def test_the_results_file_names_the_commit_and_the_date_of_its_run():
    head = "\n".join(results_header("`python tests/mutation/run.py`"))
    commit = subprocess.run(["git", "rev-parse", "HEAD"], cwd=ROOT, capture_output=True,
                            text=True).stdout.strip()
    assert commit and commit in head
    assert time.strftime("%Y-%m-%d") in head and "Not edited by hand" in head


def test_mutants_name_tests_that_exist():
    """A moved or renamed test file would make every mutant that names it 'not run'."""
    for m in MUTANTS:
        assert (ROOT / m.file).is_file(), (m.name, m.file)
        for node in m.tests:
            path, _, name = node.partition("::")
            assert (ROOT / path).is_file(), (m.name, path)
            if name:
                assert re.search(rf"def {re.escape(name.split('[')[0])}\b",
                                 (ROOT / path).read_text()), (m.name, node)  # fmt: skip


def test_mutants_change_code_that_exists():
    """Each mutant's snippet occurs exactly once in its file: a snippet the code no longer
    has would leave that place unchecked without a word."""
    for m in MUTANTS:
        assert (ROOT / m.file).read_text().count(m.old) == 1, (m.name, m.file, m.old)


def test_generated_mutants_are_reproducible_and_change_the_code():
    """A seed gives the same sample every time, a share of every module group, each a
    change of the code's syntax tree (never inside a string or a message) at a place its
    file still has, and covered by test files that exist."""
    import ast

    sample = generate(7, 3)
    assert [m.name for m in sample] == [m.name for m in generate(7, 3)]
    assert [m.name for m in sample] != [m.name for m in generate(8, 3)]
    assert len(sample) == 3 * len(GROUPS) and len({m.name for m in sample}) == len(sample)
    for m in sample:
        text = (ROOT / m.file).read_text()
        mutated = m.apply(text)
        assert mutated is not None, m.name
        assert ast.dump(ast.parse(mutated)) != ast.dump(ast.parse(text)), m.name
        assert all((ROOT / t.split("::")[0]).is_file() for t in m.tests), m.name
