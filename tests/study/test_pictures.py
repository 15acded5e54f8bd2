"""The stability pictures are legible: no two tick labels on an axis run into each other."""

from __future__ import annotations

import numpy as np
import pytest
import xarray as xr

from stabdae import plots


def drawn_figure(monkeypatch, draw, *args):
    """Run ``draw(*args)`` and return the figure it saved (drawn, so labels have sizes)."""
    import matplotlib.figure

    saved = {}
    real = matplotlib.figure.Figure.savefig

    def keep(self, *a, **k):
        saved["fig"] = self
        return real(self, *a, **k)

    monkeypatch.setattr(matplotlib.figure.Figure, "savefig", keep)
    draw(*args)
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    fig = saved["fig"]
    FigureCanvasAgg(fig).draw()  # (a closed figure keeps no canvas of its own)
    return fig


def overlapping_labels(axis, renderer) -> int:
    labels = [t for t in axis.get_ticklabels(minor=True) + axis.get_ticklabels()
              if t.get_visible() and t.get_text()]  # fmt: skip
    boxes = sorted((t.get_window_extent(renderer) for t in labels), key=lambda b: b.x0)
    return sum(1 for a, b in zip(boxes, boxes[1:]) if a.x1 > b.x0)


@pytest.mark.parametrize("low", [2e-3, 1e-3])
@pytest.mark.parametrize("draw", ["stability_map", "decision_map"])
def test_tick_labels_of_a_log_axis_spanning_a_decade_or_two_do_not_overlap(
        monkeypatch, tmp_path, draw, low):
    """τ from 2e-3 (or 1e-3) to 5e-2, a study's grid: matplotlib's own choice labelled 2,
    3, 4 and 6 × 10^k as well, and on a picture of this width they ran into each other (6
    pairs before); now 1 and 3 × 10^k, at least three of them."""
    tau = np.geomspace(low, 5e-2, 6)
    omega = np.geomspace(1.0, 1e3, 6)
    shape = (tau.size, omega.size)
    rng = np.random.default_rng(0)
    ds = xr.Dataset(
        {"fraction_stable": (("tau", "omega"), rng.uniform(size=shape)),
         "fraction_bounded": (("tau", "omega"), rng.uniform(size=shape)),
         "spectral_radius": (("tau", "omega"), np.outer(tau, omega) / 2.79),
         "decision": (("tau", "omega"), rng.integers(0, 3, size=shape).astype(np.int8)),
         "members_used": (("tau", "omega"), rng.choice([32, 64, 128], size=shape))},
        coords={"tau": ("tau", tau, {"units": "s"}), "omega": ("omega", omega, {"units": "s-1"})},
        attrs={"model": "test", "law": "baumgarte", "scheme": "rk4"},
    )  # fmt: skip
    fig = drawn_figure(monkeypatch, getattr(plots, draw), ds, tmp_path / "p.png")
    renderer = fig.canvas.get_renderer()
    for ax in fig.axes[:1] if draw == "stability_map" else fig.axes[:2]:
        assert overlapping_labels(ax.xaxis, renderer) == 0
        labels = [t.get_text() for t in ax.xaxis.get_ticklabels() if t.get_text()]
        assert len(labels) >= 3 and any("3\\times" in t for t in labels), labels


def test_the_decision_map_marks_each_undecided_cell_by_its_reason(monkeypatch, tmp_path):
    """An undecided cell carries the mark of its ``decision_reason``, and the legend
    decodes every mark drawn (and only those)."""
    from stabdae._codes import DecisionReason

    tau, omega = np.geomspace(1e-3, 5e-2, 3), np.geomspace(1.0, 1e2, 2)
    dec = np.array([[0, 2], [2, 1], [2, 2]], dtype=np.int8)
    why = np.array([[0, int(DecisionReason.NOT_RUN)], [int(DecisionReason.MAX_REACHED), 1],
                    [int(DecisionReason.NOT_RUN), int(DecisionReason.MEMBERS_UNDECIDED)]],
                   dtype=np.int8)  # fmt: skip
    ds = xr.Dataset(
        {"fraction_stable": (("tau", "omega"), np.full(dec.shape, 0.5)),
         "fraction_bounded": (("tau", "omega"), np.full(dec.shape, 0.5)),
         "decision": (("tau", "omega"), dec), "decision_reason": (("tau", "omega"), why),
         "members_used": (("tau", "omega"), np.full(dec.shape, 64))},
        coords={"tau": ("tau", tau, {"units": "s"}), "omega": ("omega", omega, {"units": "s-1"})},
        attrs={"model": "test", "law": "baumgarte", "scheme": "rk4"},
    )  # fmt: skip
    fig = drawn_figure(monkeypatch, plots.decision_map, ds, tmp_path / "p.png")
    marks = sorted(t.get_text() for t in fig.axes[0].texts)
    assert marks == ["m", "n", "n", "u"]
    legend = [t.get_text() for t in fig.axes[0].get_legend().get_texts()]
    reasons = [t for t in legend if t[:3] in ("m  ", "n  ", "u  ", "t  ")]
    assert [t[0] for t in reasons] == ["m", "u", "n"], legend  # in the codes' order
    assert any("not run" in t for t in reasons) and not any(t.startswith("t ") for t in legend)
