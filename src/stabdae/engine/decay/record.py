"""The per-member measurement record: its columns by name, each with its kind, the
reasons a member has no β and the kinds of fit.

The record is two arrays per run, one row per member: ``values`` (the float columns of
:data:`FLOATS`, indexed by ``C_<NAME>``) and ``codes`` (the integer columns of
:data:`INTEGERS`: codes, counts and flags, indexed by ``I_<NAME>``), so that no code is
ever stored as a float.  The kernels write them by these indices; Python reads them by
name (:class:`Record`).

Adding a measured column (what a contributor touches, in this order):

1. its name and kind in :data:`COLUMNS`, and its index constant below (``C_`` for a
   float, ``I_`` for an integer; looked up by name, so no order can slip);
2. where the kernel writes it: :func:`stabdae.engine.decay.member.begin` (its start
   value), :func:`~stabdae.engine.decay.member.observe` (per measured step: O(1), no
   allocation, no branch the member loop cannot vectorize) or the member's end
   (:func:`~stabdae.engine.decay.member.summarize`, the fits, the one-step map);
3. where the driver reads it, by its name: ``stabdae._ensemble_dataset``, into a dataset
   variable;
4. that variable in ``stabdae._schema.SCHEMA`` (dims, long name, units, and for a code
   its family in ``stabdae._codes``); ``docs/schema.md`` is generated from it;
5. a test from a source of truth (an exact sequence on an affine system, a closed form,
   the NumPy reference in ``tests/reference``).
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np

from ..._codes import BetaReason, FitKind, messages

#: the record's columns, each with its kind: ``"f"`` a float, ``"i"`` an integer (a code,
#: a count or a flag)
COLUMNS = (
    ("beta", "f"), ("gamma", "f"), ("floor", "f"), ("initial", "f"), ("largest", "f"),
    ("final", "f"), ("w0", "f"), ("w1", "f"), ("w2", "f"), ("w3", "f"), ("w4", "f"),
    ("fit_start", "f"), ("fit_end", "f"), ("fit_points", "i"), ("reason", "i"),
    ("fit_kind", "i"), ("shift", "f"), ("floor_reached", "i"), ("beta_predicted", "f"),
    ("d2", "f"), ("d3", "f"), ("d4", "f"),
)  # fmt: skip
#: the float columns, in the order of ``values``'s columns
FLOATS = tuple(name for name, kind in COLUMNS if kind == "f")
#: the integer columns, in the order of ``codes``'s columns
INTEGERS = tuple(name for name, kind in COLUMNS if kind == "i")
NCOLS, NCODES = len(FLOATS), len(INTEGERS)
_F = {name: i for i, name in enumerate(FLOATS)}
_I = {name: i for i, name in enumerate(INTEGERS)}
C_BETA, C_GAMMA, C_FLOOR, C_INITIAL = _F["beta"], _F["gamma"], _F["floor"], _F["initial"]
C_LARGEST, C_FINAL, C_SHIFT = _F["largest"], _F["final"], _F["shift"]
C_W0, C_W1, C_W2, C_W3, C_W4 = (_F[f"w{i}"] for i in range(5))
C_FIT_START, C_FIT_END, C_BETA_PRED = _F["fit_start"], _F["fit_end"], _F["beta_predicted"]
C_D2, C_D3, C_D4 = _F["d2"], _F["d3"], _F["d4"]
I_POINTS, I_REASON, I_KIND = _I["fit_points"], _I["reason"], _I["fit_kind"]
I_FLOOR_REACHED = _I["floor_reached"]
# the kernels index the fifths as C_W0 + window and C_D2 + window − 2
if (C_W1, C_W2, C_W3, C_W4, C_D3, C_D4) != (C_W0 + 1, C_W0 + 2, C_W0 + 3, C_W0 + 4,
                                           C_D2 + 1, C_D2 + 2):  # fmt: skip
    raise ImportError("the record's w0…w4 and d2…d4 must be consecutive columns")

# The codes as plain ints for the kernels (the table, with the messages, is
# :mod:`stabdae._codes`).
#: reason codes of ``beta_reason`` (:class:`stabdae._codes.BetaReason`)
R_FITTED, R_NO_TRANSIENT, R_STOPPED, R_NOT_DECAYING = (int(c) for c in BetaReason)
REASONS = messages(BetaReason)
#: kinds of fit (``fit_kind``, :class:`stabdae._codes.FitKind`)
K_NONE, K_EXPONENTIAL, K_POLYNOMIAL, K_OSCILLATING, K_MAP = (int(c) for c in FitKind)
KINDS = messages(FitKind)


class Record(NamedTuple):
    """The measurement record of ``members`` members: ``values`` (float columns) and
    ``codes`` (integer columns); ``record["beta"]`` is a column by name (a view)."""

    values: np.ndarray
    codes: np.ndarray

    @classmethod
    def empty(cls, members: int) -> Record:
        """Allocated, not filled: the kernels write every element of a member they begin."""
        return cls(np.empty((members, NCOLS)), np.empty((members, NCODES), dtype=np.int64))

    def __getitem__(self, name):
        if isinstance(name, str):
            if name in _F:
                return self.values[:, _F[name]]
            if name in _I:
                return self.codes[:, _I[name]]
            raise KeyError(f"no measured column {name!r}; the columns: "
                           f"{', '.join(n for n, _ in COLUMNS)}")  # fmt: skip
        return tuple.__getitem__(self, name)
