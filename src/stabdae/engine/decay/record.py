"""The per-member measurement record: its columns, the reasons a member has no β
and the kinds of fit, by name and code.

Adding a measured column (what a contributor touches, in this order):

1. its name in :data:`COLUMNS` and its index ``C_<NAME>`` at the same place in the
   unpacking below (both come from one ``range``: keep the two orders equal);
2. where the kernel writes it: :func:`stabdae.engine.decay.member.begin` (its start
   value), :func:`~stabdae.engine.decay.member.observe` (per measured step: O(1), no
   allocation, no branch the member loop cannot vectorize) or the member's end
   (:func:`~stabdae.engine.decay.member.summarize`, the fits, the one-step map);
3. where the driver reads it, by its ``C_<NAME>``: ``stabdae._ensemble``'s dataset
   builder, into a dataset variable;
4. that variable in ``stabdae._schema.SCHEMA`` (dims, long name, units, and for a code
   its family in ``stabdae._codes``); ``docs/schema.md`` is generated from it;
5. a test from a source of truth (an exact sequence on an affine system, a closed form,
   the NumPy reference in ``tests/reference``).
"""

from __future__ import annotations

from ..._codes import BetaReason, FitKind, messages

#: columns of the per-member measurement array (``measures``)
COLUMNS = ("beta", "gamma", "floor", "initial", "largest", "final", "w0", "w1", "w2", "w3",
           "w4", "fit_start", "fit_end", "fit_points", "reason", "fit_kind", "shift",
           "floor_reached", "beta_predicted", "d2", "d3", "d4")  # fmt: skip
(C_BETA, C_GAMMA, C_FLOOR, C_INITIAL, C_LARGEST, C_FINAL, C_W0, C_W1, C_W2, C_W3, C_W4,
 C_FIT_START, C_FIT_END, C_POINTS, C_REASON, C_KIND, C_SHIFT, C_FLOOR_REACHED,
 C_BETA_PRED, C_D2, C_D3, C_D4) = range(len(COLUMNS))  # fmt: skip
NCOLS = len(COLUMNS)

# The codes as plain ints for the kernels (the table, with the messages, is
# :mod:`stabdae._codes`).
#: reason codes of ``beta_reason`` (:class:`stabdae._codes.BetaReason`)
R_FITTED, R_NO_TRANSIENT, R_STOPPED, R_NOT_DECAYING = (int(c) for c in BetaReason)
REASONS = messages(BetaReason)
#: kinds of fit (``fit_kind``, :class:`stabdae._codes.FitKind`)
K_NONE, K_EXPONENTIAL, K_POLYNOMIAL, K_OSCILLATING, K_MAP = (int(c) for c in FitKind)
KINDS = messages(FitKind)
