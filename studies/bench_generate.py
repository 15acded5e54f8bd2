"""Deriving a model from its Lagrangian: minimal against redundant coordinates, expanded
against kept as the product and chain rules build it.

    python studies/bench_generate.py [--links 3 5 8] [--expanded-up-to 5] [--specs bicycle ...]

The system: a chain of N rods whose tip is held at a fixed distance from a pin.  In
minimal coordinates (the N joint angles, one constraint: the tip's distance, a square
root of squared sums of sines and cosines), derived with ``expand=True`` and
``expand=False`` (the default); in redundant coordinates (the N joints' x and y, N rod
constraints and the tip's, all quadratic).  For each: the seconds to derive and to write the code,
and the operations of the generated functions after common subexpressions
(``System.operations``).  Expanded derivations grow fast: keep ``--expanded-up-to`` small.
``--specs`` measures specs of ``kernels/specs/`` as they are written (the Whipple bicycle
in 8 minimal and in 12 redundant coordinates: ``--specs bicycle bicycle_redundant``).
"""

from __future__ import annotations

import argparse
import math
import time
from pathlib import Path

import sympy as sp

from stabdae.symbolic import System, coordinates, load_spec

SPECS = Path(__file__).resolve().parent.parent / "kernels" / "specs"


def _angles(links):
    return [0.3 * (-1) ** i for i in range(links)]


def minimal(links: int, **options) -> System:
    th, thd = coordinates(" ".join(f"th{i}" for i in range(links)))
    g, l, m = sp.symbols("g l m")
    x = y = xd = yd = kinetic = potential = 0
    for i in range(links):
        x, y = x + l * sp.sin(th[i]), y - l * sp.cos(th[i])
        xd, yd = xd + l * sp.cos(th[i]) * thd[i], yd + l * sp.sin(th[i]) * thd[i]
        kinetic += m * (xd**2 + yd**2) / 2
        potential += m * g * y
    angles = _angles(links)
    tip = (sum(math.sin(a) for a in angles), -sum(math.cos(a) for a in angles))
    r = math.hypot(tip[0] - 0.5, tip[1] + 0.2)
    return System(f"chain{links}", q=list(th), v=list(thd), lagrangian=kinetic - potential,
                  holonomic=[sp.sqrt((x - 0.5 * l) ** 2 + (y + 0.2 * l) ** 2) - r * l],
                  params={g: 9.81, l: 1.0, m: 1.0}, reference_state=angles + [0.0] * links,
                  **options)  # fmt: skip


def redundant(links: int, **options) -> System:
    q, v = coordinates(" ".join(f"x{i} y{i}" for i in range(links)))
    g, l, m = sp.symbols("g l m")
    xs, ys, xd, yd = q[0::2], q[1::2], v[0::2], v[1::2]
    kinetic = sum(m * (xd[i] ** 2 + yd[i] ** 2) / 2 for i in range(links))
    potential = sum(m * g * ys[i] for i in range(links))
    px = py = 0.0
    reference = []
    for a in _angles(links):
        px, py = px + math.sin(a), py - math.cos(a)
        reference += [px, py]
    r = math.hypot(px - 0.5, py + 0.2)
    rods = [xs[0] ** 2 + ys[0] ** 2 - l**2] + [
        (xs[i] - xs[i - 1]) ** 2 + (ys[i] - ys[i - 1]) ** 2 - l**2 for i in range(1, links)
    ]
    pin = (xs[-1] - 0.5 * l) ** 2 + (ys[-1] + 0.2 * l) ** 2 - (r * l) ** 2
    return System(f"cartesian{links}", q=list(q), v=list(v), lagrangian=kinetic - potential,
                  holonomic=rods + [pin], params={g: 9.81, l: 1.0, m: 1.0},
                  reference_state=reference + [0.0] * (2 * links), **options)  # fmt: skip


def measure(label: str, system: System) -> None:
    start = time.perf_counter()
    system.derive()
    derived = time.perf_counter()
    system.source()
    written = time.perf_counter()
    ops = system.operations
    print(f"| {label} | {system.n} | {system.m + system.k} | {derived - start:.2f} | "
          f"{written - derived:.2f} | {sum(ops.values())} | {ops.get('f_accel')} | "
          f"{ops.get('forces')} |", flush=True)  # fmt: skip


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--links", type=int, nargs="+", default=[3, 5, 8])
    ap.add_argument("--expanded-up-to", type=int, default=5,
                    help="largest chain derived expanded (minimal coordinates)")
    ap.add_argument("--specs", nargs="*", default=[], metavar="NAME",
                    help="specs of kernels/specs to measure as written")
    args = ap.parse_args(argv)
    print("| system | n | m + k | derive s | code s | operations | f_accel | forces |")
    print("|---|---:|---:|---:|---:|---:|---:|---:|")
    for links in args.links:
        measure(f"{links} links, redundant", redundant(links, simplify=False))
        measure(f"{links} links, minimal, kept", minimal(links, simplify=False, expand=False))
        if links <= args.expanded_up_to:
            measure(f"{links} links, minimal, expanded", minimal(links, simplify=False,
                                                                  expand=True))
    for name in args.specs:
        measure(f"`{name}` spec", load_spec(SPECS / f"{name}.py"))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
