"""The cost-layer histogram: counts, the colour-limit band, non-finite values."""

from __future__ import annotations

import numpy as np

from app.histogram import histogram_data


def _at(h, x: float) -> tuple[float, float]:
    """Return (count, band) of the step just right of ``x``."""
    i = np.flatnonzero(h.x <= x)[-1]
    return float(h.counts[i]), float(h.limits[i])


def test_counts_match_numpy_per_bin():
    rng = np.random.default_rng(3)
    values = np.concatenate([[0.0, 2.0], rng.uniform(0.0, 2.0, 998)]).astype(np.float32)
    h = histogram_data(values, 0.5, 1.5, bins=10)
    assert np.all(np.diff(h.x) >= 0)  # uPlot needs a sorted x
    assert len(h.x) == len(h.counts) == len(h.limits)
    expected, edges = np.histogram(values, bins=10, range=(0.0, 2.0))
    mids = (edges[:-1] + edges[1:]) / 2
    assert [_at(h, m)[0] for m in mids] == expected.tolist()
    assert h.counts[0] == 0 and h.counts[-1] == 0  # the outline closes at both ends
    assert h.n_finite == 1000 and h.note == ""


def test_the_band_spans_the_colour_limits():
    values = np.linspace(0.0, 1.0, 101)
    h = histogram_data(values, 0.25, 0.75, bins=4)
    top = h.limits.max()
    assert top > 0
    assert _at(h, 0.1)[1] == 0
    assert _at(h, 0.3)[1] == top
    assert _at(h, 0.7)[1] == top
    assert _at(h, 0.8)[1] == 0
    assert 0.25 in h.x and 0.75 in h.x


def test_limits_outside_the_data_widen_the_range():
    h = histogram_data(np.array([0.4, 0.5, 0.6]), 0.0, 2.0)
    assert h.x[0] == 0.0 and h.x[-1] == 2.0


def test_nan_and_inf_are_counted_not_binned():
    values = np.array([0.0, 1.0, np.nan, np.inf, np.inf, -np.inf], np.float32)
    h = histogram_data(values, 0.0, 1.0)
    assert (h.n_finite, h.n_nan, h.n_pos_inf, h.n_neg_inf) == (2, 1, 2, 1)
    assert "2 lethal (+inf)" in h.note and "1 NaN" in h.note
    assert np.isfinite(h.x).all() and np.isfinite(h.counts).all()


def test_a_constant_or_empty_layer_still_draws():
    for values in (np.zeros(10), np.zeros(0), np.full(3, np.nan)):
        h = histogram_data(values, 0.0, 0.0)
        assert h.x[-1] > h.x[0]
        assert np.isfinite(h.x).all()
