"""Bricard's mechanism (IFToMM benchmark A04) with its redundant constraint left out, generated.

The scene `bricard` with the same coordinates, Lagrangian and start, and 14 of its 15
constraints: the loop's closure along x is dropped.  Along the whole motion that row is a
combination of the others (the full set has rank 14 there, and the 14 kept rows have
rank 14 at every state of the motion, their smallest singular value at least 0.12 of the
largest), so the kept rows define the same one-degree-of-freedom motion near it, S is
regular and the default L D Lᵀ multiplier, ensembles and studies run it.  Off the
manifold the dropped row's residual is, to first order, a combination of the kept ones
and decays with them (tested).  See `bricard` for the mechanism.
"""

from pathlib import Path

from stabdae.symbolic import System, load_spec

DROPPED = 10  # the full set's rows: 5 lengths, 5 perpendiculars, closure x, y, z, 2 axis


def _independent():
    full = load_spec(Path(__file__).with_name("bricard.py"))
    keep = [i for i in range(full.m) if i != DROPPED]
    return System(
        "bricard_independent",
        q=full.q,
        v=full.v,
        lagrangian=full.L,
        holonomic=[full.f[i] for i in keep],
        params=full.params,
        reference_state=full.x_ref,
        coordinate_units=full.coordinate_units,
        constraint_units=[full.constraint_units[i] for i in keep],
        energy_units=full.energy_units,
        simplify=False,
        expand=False,
        description=__doc__,
    )


system = _independent()
