"""The structure of ``F = [f_q ; h_v]``, ``h_q`` and ``S = F M⁻¹ Fᵀ`` as index lists.

A model with many coordinates usually couples each constraint to a few of them: a charge
on a sphere to its own three, a link of a chain to its two ends.  The dense right-hand side
forms ``S`` with ``r² n / 2`` multiply-adds and factors it with ``r³ / 6``; Fekete's ``S``
(20 charges, n = 60) is diagonal, and its whole constraint part is 20 divisions.

:func:`structure` turns boolean patterns into the index lists the sparse right-hand side
(:mod:`.rhs`) loops over: the rows and the columns of ``F``, the products that make each
entry of ``S``, and the L D Lᵀ factor's pattern with the fill its elimination creates (no
reordering: the constraints' own order, which for a chain is already the banded one).
Every list visits its terms in the order of the dense loops, so that the sparse path does
the dense path's arithmetic minus the terms that are structurally zero; the two agree to
the sign of a zero.

The lists are NumPy arrays captured by the compiled functions as constants; their loops
have constant bounds, so LLVM unrolls them where they are short and the code grows with
the number of non-zeros, not with ``n r²``.
"""

from __future__ import annotations

from collections import namedtuple

import numpy as np

__all__ = ["Structure", "structure", "dense_cost", "sparse_cost"]

Structure = namedtuple(
    "Structure",
    # rows of F (CSR): F[i, fcol[fptr[i]:fptr[i+1]]]; columns of F (CSC): F[frow[..], j]
    "fptr fcol cptr crow "
    # rows of h_q (CSR)
    "hqptr hqcol "
    # S's lower triangle and the L factor's fill, as pairs (i, c): S[i, c] =
    # Σ_j F[i, j] Y[j, c] over j in sj[sptr[e]:sptr[e+1]]
    "si sc sptr sj "
    # the factor: strict lower entries of row j: lcol[lptr[j]:lptr[j+1]]; for each of them
    # (entry e) the q < p with L[j, q] and L[p, q]: oq[optr[e]:optr[e+1]]; strict lower
    # entries of column i: lrow[ltptr[i]:ltptr[i+1]]
    "lptr lcol optr oq ltptr lrow "
    "nnz_f nnz_s nnz_l",
)
Structure.__doc__ = """Index lists of one model's sparsity (see :func:`structure`)."""


def _csr(pattern: np.ndarray):
    rows, cols = np.nonzero(pattern)  # row-major order: rows ascending, then columns
    ptr = np.zeros(pattern.shape[0] + 1, dtype=np.int64)
    np.add.at(ptr, rows + 1, 1)
    return np.cumsum(ptr), cols.astype(np.int64)


def fill_pattern(s_lower: np.ndarray) -> np.ndarray:
    """The lower triangle (diagonal included) of ``L + D`` for a symmetric matrix whose
    lower pattern is ``s_lower``, eliminated in its own order."""
    pat = np.tril(np.asarray(s_lower, dtype=bool)) | np.eye(s_lower.shape[0], dtype=bool)
    r = pat.shape[0]
    for p in range(r):
        below = np.flatnonzero(pat[p + 1:, p]) + p + 1
        if below.size > 1:
            pat[np.ix_(below, below)] |= np.tril(np.ones((below.size, below.size), dtype=bool))
    return pat


def structure(f_pattern: np.ndarray, hq_pattern: np.ndarray | None = None) -> Structure:
    """Index lists for ``F``'s pattern ``f_pattern`` (r × n, rows ``f_q`` then ``h_v``) and
    ``h_q``'s (k × n), for a mass matrix that is diagonal or the identity (so that
    ``Y = M⁻¹ Fᵀ`` has ``Fᵀ``'s pattern)."""
    F = np.asarray(f_pattern, dtype=bool)
    r, n = F.shape
    fptr, fcol = _csr(F)
    cptr, crow = _csr(F.T)
    hq = np.zeros((0, n), dtype=bool) if hq_pattern is None else np.asarray(hq_pattern, bool)
    hqptr, hqcol = _csr(hq)
    common = (F.astype(np.int64) @ F.T.astype(np.int64)) > 0  # S's pattern
    L = fill_pattern(common)
    si, sc, sptr, sj = [], [], [0], []
    for i in range(r):
        for c in range(i + 1):
            if L[i, c]:  # S's entries and the fill, which starts from zero
                si.append(i)
                sc.append(c)
                sj.extend(np.flatnonzero(F[i] & F[c]).tolist())
                sptr.append(len(sj))
    strict = np.tril(L, -1)
    lptr, lcol = _csr(strict)
    optr, oq = [0], []
    for j in range(r):
        for p in lcol[lptr[j]:lptr[j + 1]]:
            oq.extend(np.flatnonzero(strict[j, :p] & strict[p, :p]).tolist())
            optr.append(len(oq))
    ltptr, lrow = _csr(strict.T)
    i64 = lambda a: np.asarray(a, dtype=np.int64)  # noqa: E731
    return Structure(fptr, fcol, cptr, crow, hqptr, hqcol, i64(si), i64(sc), i64(sptr),
                     i64(sj), lptr, lcol, i64(optr), i64(oq), ltptr, lrow, int(F.sum()),
                     int(common[np.tril_indices(r)].sum()), int(strict.sum()))  # fmt: skip


def dense_cost(n: int, r: int) -> int:
    """Multiply-adds of the dense path's constraint part per evaluation: ``S``'s lower
    triangle, its factor, the products with ``F`` and ``Y``."""
    return n * r * (r + 1) // 2 + r ** 3 // 6 + 3 * n * r


def sparse_cost(st: Structure) -> int:
    """The same count for the sparse path."""
    return int(st.sj.size + st.oq.size + st.lcol.size + 3 * st.nnz_f)
