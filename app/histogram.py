"""A histogram of the cost layer on screen, with its colour limits marked, as a uPlot chart.

viser 1.1.1 ships uPlot (``gui.add_uplot``) and needs no extra dependency for it. uPlot draws
lines between (x, y) points over one shared x array, so both series are step functions sampled
twice at every breakpoint (the value just left and just right of it), which gives vertical
edges: the histogram's bars and the band between the colour limits.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import viser
import viser.uplot

#: Bins of the histogram; enough to see the shape, few enough to send on every change.
BINS = 64


@dataclass(frozen=True, eq=False)
class HistogramData:
    """Carry the chart's arrays and what the chart cannot show (non-finite values)."""

    x: npt.NDArray[np.float64]  #: [M] cost values, non-decreasing (breakpoints, each twice)
    counts: npt.NDArray[np.float64]  #: [M] vertices per bin, as a step function of x
    limits: npt.NDArray[np.float64]  #: [M] the tallest count between vmin and vmax, else 0
    n_finite: int
    n_nan: int
    n_pos_inf: int
    n_neg_inf: int

    @property
    def note(self) -> str:
        """Return the non-finite counts in words ("" when every value is finite)."""
        parts = []
        if self.n_pos_inf:
            parts.append(f"{self.n_pos_inf:,} lethal (+inf)")
        if self.n_neg_inf:
            parts.append(f"{self.n_neg_inf:,} at -inf")
        if self.n_nan:
            parts.append(f"{self.n_nan:,} NaN")
        return ", ".join(parts)


def _steps(breaks: npt.NDArray[np.float64], values: npt.NDArray[np.float64]) -> np.ndarray:
    """Return a step function's samples at each breakpoint: left limit, then right limit.

    ``values[i]`` holds between ``breaks[i]`` and ``breaks[i + 1]``; outside it is 0.
    """
    left = np.concatenate([[0.0], values])
    right = np.concatenate([values, [0.0]])
    return np.stack([left, right], axis=1).reshape(-1)


def histogram_data(
    values: npt.ArrayLike, vmin: float, vmax: float, *, bins: int = BINS
) -> HistogramData:
    """Return the histogram of a layer's finite values with the band ``[vmin, vmax]``.

    The bins span the finite values and the limits together, so limits outside the data are
    still drawn. NaN and +-inf are counted, not binned.

    Parameters
    ----------
    values : float [N] per-vertex costs (NaN and +-inf allowed)
    vmin, vmax : the colour limits (swapped when vmin > vmax)
    """
    v = np.asarray(values, dtype=np.float64).reshape(-1)
    finite = np.isfinite(v)
    data = v[finite]
    n_nan = int(np.count_nonzero(np.isnan(v)))
    n_pos = int(np.count_nonzero(v == math.inf))
    n_neg = int(np.count_nonzero(v == -math.inf))
    lo_lim, hi_lim = sorted((float(vmin), float(vmax)))
    bounds = [x for x in (lo_lim, hi_lim) if math.isfinite(x)]
    if len(data):
        bounds += [float(data.min()), float(data.max())]
    lo, hi = (min(bounds), max(bounds)) if bounds else (0.0, 1.0)
    if hi - lo <= 1e-12 * max(1.0, abs(lo)):
        lo, hi = lo - 0.5, hi + 0.5
    counts, edges = np.histogram(data, bins=bins, range=(lo, hi))
    band_lo = min(max(lo_lim, lo), hi)
    band_hi = max(min(hi_lim, hi), lo)
    breaks = np.unique(np.concatenate([edges, [band_lo, band_hi]]))
    mids = (breaks[:-1] + breaks[1:]) / 2
    bin_ids = np.clip(np.searchsorted(edges, mids, side="right") - 1, 0, bins - 1)
    step_counts = counts[bin_ids].astype(np.float64)
    top = float(max(counts.max(initial=0), 1))
    in_band = (mids >= band_lo) & (mids <= band_hi) & (band_hi > band_lo)
    band = np.where(in_band, top, 0.0)
    return HistogramData(
        x=np.repeat(breaks, 2),
        counts=_steps(breaks, step_counts),
        limits=_steps(breaks, band),
        n_finite=len(data),
        n_nan=n_nan,
        n_pos_inf=n_pos,
        n_neg_inf=n_neg,
    )


def _title(name: str, h: HistogramData, vmin: float, vmax: float) -> str:
    note = f" ({h.note})" if h.note else ""
    return f"{name}: colours {vmin:.3g} to {vmax:.3g}{note}"


def _scales(h: HistogramData) -> dict[str, viser.uplot.Scale]:
    """Return fixed axis ranges: counts from 0 (asinh: linear near 0, log-like above)."""
    top = float(max(h.counts.max(initial=0.0), 1.0))
    return {
        "x": {"time": False, "auto": False, "range": (float(h.x[0]), float(h.x[-1]))},
        "y": {"distr": 4, "asinh": 1, "auto": False, "range": (0.0, top * 1.15)},
    }


class LayerHistogram:
    """Show the histogram of the active cost layer under the colour bar."""

    def __init__(self, gui: viser.GuiApi) -> None:
        empty = histogram_data(np.zeros(0, np.float32), 0.0, 1.0)
        self._key: tuple[object, ...] | None = None
        self._owner: object = None
        self.handle = gui.add_uplot(
            (empty.x, empty.counts, empty.limits),
            (
                viser.uplot.Series(label="cost"),
                viser.uplot.Series(
                    label="vertices", stroke="#555", fill="rgba(90, 90, 90, 0.35)", width=1.0
                ),
                viser.uplot.Series(
                    label="colour range",
                    stroke="rgba(230, 120, 0, 0.9)",
                    fill="rgba(255, 160, 0, 0.2)",
                    width=1.0,
                ),
            ),
            title="histogram",
            scales=_scales(empty),
            legend={"show": False},
            aspect=1.6,
            padding=(12, 16, 0, 0),
        )

    @property
    def visible(self) -> bool:
        """Return whether the chart is shown."""
        return bool(self.handle.visible)

    @visible.setter
    def visible(self, on: bool) -> None:
        self.handle.visible = on

    def show(self, name: str, values: npt.NDArray[np.floating], vmin: float, vmax: float) -> None:
        """Draw ``values`` with the limits; skip the work when nothing changed."""
        owner = values.base if values.base is not None else values  # the stored array
        key = (name, id(owner), len(values), float(vmin), float(vmax))
        if key == self._key and self._owner is owner:
            return
        h = histogram_data(values, vmin, vmax)
        self.handle.scales = _scales(h)
        self.handle.data = (h.x, h.counts, h.limits)
        self.handle.title = _title(name, h, vmin, vmax)
        self._key = key
        self._owner = owner
