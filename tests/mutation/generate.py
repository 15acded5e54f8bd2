"""Operator mutants at random points of the measurement, verdict, boundary, theory,
adaptive, sparsity, study and schema code, drawn with a seed, beside the hand-written list
of ``mutants.py``: the hand list is written by the hands that wrote the tests; a random
sample says how much of the code the tests pin.

Operators (each a single change on one line, the rest of the file untouched):

* ``compare``: a comparison's boundary (``<`` ↔ ``<=``, ``>`` ↔ ``>=``) or its negation
  (``<`` → ``>=``, ``==`` ↔ ``!=``, ``in`` ↔ ``not in``, ``is`` ↔ ``is not``);
* ``arith``: ``+`` ↔ ``-``, ``*`` ↔ ``/``, ``//`` → ``*``, ``**`` → ``*``;
* ``drop``: a binary operation replaced by its left operand (a dropped term or factor);
* ``bool``: ``and`` ↔ ``or``; ``not x`` → ``x``; ``-x`` → ``x``;
* ``constant``: an integer ``n`` → ``n + 1``, a float ``x`` → ``2x`` (``0.0`` → ``1.0``);
* ``index``: ``a[i]`` → ``a[i + 1]``, ``range(…, b)`` → ``range(…, b - 1)`` (off by one);
* ``swap``: a call's first two positional arguments swapped (neither a string).

Never mutated: docstrings and other strings, messages (``raise`` statements, warnings,
f-strings, progress and log calls), imports and annotations: a change there is not a
change of the numbers.

    python tests/mutation/run.py --generate 2026 --per-module 8    # run a sample
    python tests/mutation/generate.py 2026 --per-module 8          # list it
"""

from __future__ import annotations

import argparse
import ast
import random
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from mutants import Mutant  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
S = "src/stabdae/"
D = "tests/drivers/"

#: the module groups sampled (one group: one share of the sample) and the tests that cover
#: each, those that compile least first (``pytest -x`` stops at the first failure; a
#: survivor runs them all)
B = "tests/theory/test_boundary.py::"
V = D + "test_verdict.py::"
GROUPS = {
    "measures": ([S + "_measures.py"],
                 (D + "test_verdict_reference.py",
                  D + "test_measurement.py::test_wilson_and_median_intervals",
                  V + "test_verdict_rule_with_the_theory",
                  V + "test_verdict_rule_at_rho_above_one_and_without_theory",
                  V + "test_stability_radius_is_censored_or_bracketed",
                  B + "test_roundoff_growing_with_the_state_is_not_growth",
                  V + "test_affine_system_decays_exactly_and_its_transient_is_no_divergence",
                  V + "test_double_pendulum_is_stable_over_its_irregular_motion")),
    "decay": ([S + f"engine/decay/{f}.py" for f in ("fit", "ladder", "member", "onestep",
                                                   "traces")],
              ("tests/engine/test_decay_reference.py", D + "test_verdict_reference.py",
               D + "test_measurement.py::test_beta_of_velocity_and_position_constraints"
               "_together_matches_the_prediction",
               "tests/engine/test_decay.py", D + "test_measurement.py")),
    "boundary": ([S + "_boundary.py"], ("tests/theory/test_boundary.py",)),
    "theory": ([S + "theory.py"],
               (B + "test_recommended_gains_in_closed_form",
                B + "test_condition4_and_forced_gain_against_closed_forms",
                B + "test_condition4_with_a_non_symmetric_map_and_constant_forcing",
                D + "test_adaptive_ensemble.py::test_expm_by_products_is_scipys_to_roundoff",
                "tests/theory/test_theory.py", V + "test_fifth_bounds_in_closed_form",
                "tests/theory/test_boundary.py")),
    "ensemble": ([S + "_ensemble.py"],
                 (D + "test_verdict_reference.py", D + "test_argument_errors.py",
                  D + "test_measurement.py", D + "test_ensemble.py")),
    "adaptive": ([S + "engine/rk/adaptive.py", S + "engine/ensemble/lanes.py"],
                 (D + "test_adaptive_ensemble.py", D + "test_hard_cases.py")),
    "sparsity": ([S + "engine/sparsity.py"], ("tests/engine/test_sparsity.py",)),
    "study": ([S + "study/run.py"],
              ("tests/study/test_run.py", "tests/study/test_cli.py",
               "tests/study/test_study.py::test_a_theorem5_search_study_has_no_path_theory")),
    "schema": ([S + "_schema.py"], (D + "test_schema.py", "tests/meta/test_docs.py")),
}  # fmt: skip

_BOUNDARY = {ast.Lt: "<=", ast.LtE: "<", ast.Gt: ">=", ast.GtE: ">"}
_NEGATION = {ast.Lt: ">=", ast.LtE: ">", ast.Gt: "<=", ast.GtE: "<", ast.Eq: "!=",
             ast.NotEq: "==", ast.In: "not in", ast.NotIn: "in", ast.Is: "is not",
             ast.IsNot: "is"}  # fmt: skip
_SYMBOL = {ast.Lt: "<", ast.LtE: "<=", ast.Gt: ">", ast.GtE: ">=", ast.Eq: "==",
           ast.NotEq: "!=", ast.In: "in", ast.NotIn: "not in", ast.Is: "is",
           ast.IsNot: "is not", ast.Add: "+", ast.Sub: "-", ast.Mult: "*", ast.Div: "/",
           ast.FloorDiv: "//", ast.Pow: "**"}  # fmt: skip
_ARITH = {ast.Add: "-", ast.Sub: "+", ast.Mult: "/", ast.Div: "*", ast.FloorDiv: "*",
          ast.Pow: "*"}  # fmt: skip
#: calls whose arguments are messages, not numbers
_QUIET_CALLS = {"warn", "log", "say", "print", "note", "describe", "StudyError",
                "ModelError", "LawError"}  # fmt: skip


def _silent_nodes(tree) -> set[int]:
    """Ids of the nodes inside messages, docstrings, imports and annotations."""
    out: set[int] = set()

    def mark(node):
        out.update(id(n) for n in ast.walk(node))

    for node in ast.walk(tree):
        if isinstance(node, (ast.Raise, ast.JoinedStr, ast.Import, ast.ImportFrom,
                             ast.Assert)):  # fmt: skip
            mark(node)
        elif isinstance(node, ast.Call):
            f = node.func
            name = f.attr if isinstance(f, ast.Attribute) else getattr(f, "id", "")
            if name in _QUIET_CALLS:
                mark(node)
        elif isinstance(node, (ast.arg, ast.AnnAssign)) and node.annotation is not None:
            mark(node.annotation)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
            if node.returns is not None:
                mark(node.returns)
            for d in node.decorator_list:
                mark(d)
    return out


def _has_text(node) -> bool:
    """Whether an expression builds text (a string operand): a message, not a number."""
    return any(isinstance(n, ast.JoinedStr) or (isinstance(n, ast.Constant)
                                                and isinstance(n.value, str))
               for n in ast.walk(node))  # fmt: skip


def _between(lines, a, b) -> tuple[int, int, str] | None:
    """The text between the end of node ``a`` and the start of ``b`` on one line."""
    if a.end_lineno != b.lineno:
        return None
    return a.end_lineno, a.end_col_offset, lines[a.end_lineno - 1][a.end_col_offset:b.col_offset]


def _op_change(lines, left, right, old_sym, new_sym):
    """Replace the operator ``old_sym`` between ``left`` and ``right`` by ``new_sym``."""
    got = _between(lines, left, right)
    if got is None:
        return None
    line, col, text = got
    pad = f" {old_sym} " if f" {old_sym} " in text else old_sym
    at = text.find(pad)
    if at < 0 or text.count(pad) != 1:
        return None
    return line, col + at, pad, pad.replace(old_sym, new_sym)


def _segment(lines, node):
    if node.lineno != node.end_lineno:
        return None
    return lines[node.lineno - 1][node.col_offset:node.end_col_offset]


def candidates(path: Path) -> list[tuple[int, int, str, str, str]]:
    """Every mutation of one file: ``(line, col, old, new, what)``."""
    text = path.read_text()
    lines = text.splitlines()
    tree = ast.parse(text)
    silent = _silent_nodes(tree)
    docstrings = {id(n.body[0].value) for n in ast.walk(tree)
                  if isinstance(n, (ast.Module, ast.FunctionDef, ast.ClassDef))
                  and n.body and isinstance(n.body[0], ast.Expr)}  # fmt: skip
    out = []
    for node in ast.walk(tree):
        if id(node) in silent or id(node) in docstrings:
            continue
        if isinstance(node, ast.Compare) and len(node.ops) == 1:
            op = type(node.ops[0])
            for table, what in ((_BOUNDARY, "boundary"), (_NEGATION, "negation")):
                if op in table:
                    c = _op_change(lines, node.left, node.comparators[0], _SYMBOL[op], table[op])
                    if c:
                        out.append((*c, f"compare ({what}): {_SYMBOL[op]} -> {table[op]}"))
        elif (isinstance(node, ast.BinOp) and type(node.op) in _ARITH
              and not _has_text(node)):  # fmt: skip
            sym = _SYMBOL[type(node.op)]
            c = _op_change(lines, node.left, node.right, sym, _ARITH[type(node.op)])
            if c:
                out.append((*c, f"arith: {sym} -> {_ARITH[type(node.op)]}"))
            whole, left = _segment(lines, node), _segment(lines, node.left)
            if whole and left:
                out.append((node.lineno, node.col_offset, whole, f"({left})",
                            f"drop: {whole} -> {left}"))  # fmt: skip
        elif isinstance(node, ast.BoolOp) and len(node.values) == 2:
            sym = "and" if isinstance(node.op, ast.And) else "or"
            c = _op_change(lines, node.values[0], node.values[1], sym,
                           "or" if sym == "and" else "and")  # fmt: skip
            if c:
                out.append((*c, f"bool: {c[2].strip()} -> {c[3].strip()}"))
        elif isinstance(node, ast.UnaryOp) and isinstance(node.op, (ast.Not, ast.USub)):
            whole, inner = _segment(lines, node), _segment(lines, node.operand)
            if whole and inner:
                out.append((node.lineno, node.col_offset, whole, f"({inner})",
                            f"bool: {whole} -> {inner}"))  # fmt: skip
        elif (isinstance(node, ast.Constant) and type(node.value) in (int, float)
              and node.lineno == node.end_lineno):  # fmt: skip
            old = _segment(lines, node)
            v = node.value
            new = repr(v + 1) if isinstance(v, int) else repr(2.0 * v if v else 1.0)
            out.append((node.lineno, node.col_offset, old, new, f"constant: {old} -> {new}"))
        elif isinstance(node, ast.Subscript) and not isinstance(node.slice, ast.Slice):
            idx = _segment(lines, node.slice)
            if idx and isinstance(node.slice, (ast.Name, ast.BinOp)):
                out.append((node.slice.lineno, node.slice.col_offset, idx, f"{idx} + 1",
                            f"index: [{idx}] -> [{idx} + 1]"))  # fmt: skip
        elif isinstance(node, ast.Call):
            name = getattr(node.func, "id", "")
            if name == "range" and node.args:
                last = node.args[-1]
                seg = _segment(lines, last)
                if seg:
                    out.append((last.lineno, last.col_offset, seg, f"({seg}) - 1",
                                f"index: range bound {seg} -> {seg} - 1"))  # fmt: skip
            args = [a for a in node.args if not isinstance(a, ast.Starred)]
            if len(args) >= 2 and len(args) == len(node.args):
                a, b = args[0], args[1]
                sa, sb = _segment(lines, a), _segment(lines, b)
                mid = _between(lines, a, b)
                labels = any(isinstance(x, ast.Constant) and isinstance(x.value, str)
                             for x in (a, b))  # a name or a label: no number changes
                if sa and sb and sa != sb and mid and a.lineno == b.end_lineno and not labels:
                    old = lines[a.lineno - 1][a.col_offset:b.end_col_offset]
                    out.append((a.lineno, a.col_offset, old, sb + mid[2] + sa,
                                f"swap: ({sa}, {sb}) -> ({sb}, {sa})"))  # fmt: skip
    return out


def _changes_code(text: str, tree: str, m: Mutant) -> bool:
    """The mutated file parses and its syntax tree differs from ``tree`` (the file's,
    dumped): no change inside a string."""
    mutated = m.apply(text)
    try:
        return mutated is not None and ast.dump(ast.parse(mutated)) != tree
    except SyntaxError:
        return False


def generate(seed: int, per_group: int) -> list[Mutant]:
    """``per_group`` mutants of each group of :data:`GROUPS`, drawn with ``seed`` (at most
    one per line)."""
    rng = random.Random(seed)
    out = []
    for group, (files, tests) in GROUPS.items():
        texts = {f: (ROOT / f).read_text() for f in files}
        trees = {f: ast.dump(ast.parse(texts[f])) for f in files}
        pool = [(f, c) for f in files for c in candidates(ROOT / f)]
        rng.shuffle(pool)
        lines_used = set()
        for f, (line, col, old, new, what) in pool:
            if (f, line) in lines_used:
                continue
            stem = Path(f).stem.lstrip("_")
            m = Mutant(f"g{seed}-{group}-{stem}-{line}", f, old, new, tests, what, line=line,
                       col=col)  # fmt: skip
            if not _changes_code(texts[f], trees[f], m):
                continue
            lines_used.add((f, line))
            out.append(m)
            if len(lines_used) == per_group:
                break
    return out


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("seed", type=int)
    ap.add_argument("--per-module", type=int, default=8, help="mutants per module group")
    args = ap.parse_args(argv)
    for m in generate(args.seed, args.per_module):
        print(f"{m.name:36s} {m.file}:{m.line}: {m.what}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
