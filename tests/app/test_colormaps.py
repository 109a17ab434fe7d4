import numpy as np
import pytest

from app.colormaps import (
    COLORMAP_NAMES,
    SPECIAL_COLORS,
    colorbar_png,
    colorize,
    colormap_lut,
    layer_stats,
    robust_limits,
)


@pytest.mark.parametrize("cmap", COLORMAP_NAMES)
def test_special_values_get_their_own_colours(cmap):
    values = np.array([0.0, 0.5, 1.0, np.nan, np.inf, -np.inf], np.float32)
    rgb = colorize(values, 0.0, 1.0, cmap).astype(int)
    lut = colormap_lut(cmap).astype(int)
    assert (rgb[0] == lut[0]).all()
    assert (rgb[2] == lut[255]).all()
    nan, pos, neg = (np.array(c) for c in SPECIAL_COLORS[cmap])
    assert (rgb[3] == nan).all()
    assert (rgb[4] == pos).all()
    assert (rgb[5] == neg).all()
    # none of the three is (nearly) a colour of the scale itself
    for c in (nan, pos, neg):
        assert np.abs(lut - c).sum(axis=1).min() > 100


def test_limits_clip_and_default_to_robust_percentiles():
    values = np.concatenate([np.linspace(0, 1, 1000), [1e6, np.nan, np.inf]]).astype(np.float32)
    stats = layer_stats(values)
    assert stats.n_nan == 1
    assert stats.n_posinf == 1
    assert stats.finite_max == pytest.approx(1e6)
    lo, hi = robust_limits(stats)
    assert 0.0 <= lo < 0.05
    assert 0.95 < hi <= 1.0  # the outlier does not squash the scale
    rgb = colorize(values, lo, hi, "viridis")
    assert (rgb[1000] == colormap_lut("viridis")[255]).all()  # 1e6 clipped to the top


def test_constant_layer_has_a_usable_range():
    lo, hi = robust_limits(layer_stats(np.full(10, 3.0, np.float32)))
    assert hi > lo


def test_colorbar_is_an_image_of_the_colormap():
    img = colorbar_png(0.0, 2.0, "rainbow", width=200)
    assert img.shape[1] == 200
    assert img.shape[2] == 3
    row = img[10, 10:190].astype(int)
    lut = colormap_lut("rainbow").astype(int)
    assert np.abs(row[0] - lut[0]).sum() < 30
    assert np.abs(row[-1] - lut[255]).sum() < 30
