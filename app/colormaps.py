"""Colormaps and the colouring of per-vertex cost layers (NaN, +inf, -inf: own colours)."""

from __future__ import annotations

import functools
import io
import json
from dataclasses import dataclass
from importlib import resources

import numpy as np
import numpy.typing as npt
from PIL import Image, ImageDraw, ImageFont

RGB = tuple[int, int, int]

#: Per colormap, colours for values off the scale: (NaN = unknown, +inf = lethal, -inf), each
#: chosen to appear nowhere in that colormap so the three stay distinguishable from any value.
SPECIAL_COLORS: dict[str, tuple[RGB, RGB, RGB]] = {
    "viridis": ((255, 0, 255), (220, 0, 0), (255, 255, 255)),
    "cividis": ((255, 0, 255), (220, 0, 0), (255, 255, 255)),
    "inferno": ((0, 200, 0), (0, 90, 255), (0, 255, 255)),
    "turbo": ((255, 255, 255), (0, 0, 0), (128, 128, 128)),
    "rainbow": ((255, 255, 255), (0, 0, 0), (128, 128, 128)),
    "jet": ((255, 255, 255), (0, 0, 0), (128, 128, 128)),
    "gray": ((255, 0, 255), (220, 0, 0), (0, 160, 255)),
}

#: Dropdown order: "viridis" is perceptual, "rainbow" is what the Mesh Tools paper uses.
COLORMAP_NAMES = ("viridis", "cividis", "inferno", "turbo", "rainbow", "jet", "gray")


@functools.cache
def colormap_lut(name: str) -> npt.NDArray[np.uint8]:
    """Return the 256 x 3 uint8 lookup table of a shipped colormap."""
    text = resources.files("static").joinpath("colormaps.json").read_text()
    maps = json.loads(text)["maps"]
    if name not in maps:
        raise KeyError(f"unknown colormap {name!r}; known: {', '.join(sorted(maps))}")
    return np.asarray(maps[name], dtype=np.uint8)


@dataclass(frozen=True)
class LayerStats:
    """What the colour limits and the legend need to know about a layer."""

    finite_min: float
    finite_max: float
    p2: float
    p98: float
    n_nan: int
    n_posinf: int
    n_neginf: int


def layer_stats(values: npt.NDArray[np.floating]) -> LayerStats:
    """Summarise a layer: finite range, robust 2/98 % percentiles, NaN and inf counts."""
    v = np.asarray(values, dtype=np.float64)
    finite = v[np.isfinite(v)]
    if len(finite):
        lo, hi = float(finite.min()), float(finite.max())
        p2, p98 = (float(x) for x in np.percentile(finite, [2.0, 98.0]))
    else:
        lo = hi = p2 = p98 = 0.0
    return LayerStats(
        lo,
        hi,
        p2,
        p98,
        int(np.isnan(v).sum()),
        int(np.isposinf(v).sum()),
        int(np.isneginf(v).sum()),
    )


def robust_limits(stats: LayerStats) -> tuple[float, float]:
    """Return default colour limits: the 2nd and 98th percentiles, widened if they coincide."""
    lo, hi = stats.p2, stats.p98
    if hi <= lo:
        lo, hi = stats.finite_min, stats.finite_max
    if hi <= lo:
        hi = lo + 1.0
    return lo, hi


def colorize(
    values: npt.NDArray[np.floating], vmin: float, vmax: float, cmap: str = "viridis"
) -> npt.NDArray[np.uint8]:
    """Map values to RGB through ``cmap`` clipped to [vmin, vmax]; NaN/+inf/-inf get fixed colours.

    Returns
    -------
    uint8 [N, 3]
    """
    lut = colormap_lut(cmap)
    v = np.asarray(values, dtype=np.float32)
    span = float(vmax - vmin) if vmax > vmin else 1.0
    with np.errstate(invalid="ignore"):
        t = np.clip((v - np.float32(vmin)) * np.float32(255.0 / span), 0, 255)
    finite = np.isfinite(v)
    idx = np.where(finite, t, 0).astype(np.uint8)
    rgb = lut[idx]
    nan_rgb, posinf_rgb, neginf_rgb = SPECIAL_COLORS[cmap]
    rgb[np.isnan(v)] = nan_rgb
    rgb[np.isposinf(v)] = posinf_rgb
    rgb[np.isneginf(v)] = neginf_rgb
    return rgb


def colorbar_png(
    vmin: float, vmax: float, cmap: str, *, width: int = 300, height: int = 46
) -> npt.NDArray[np.uint8]:
    """Draw a horizontal colour bar with min/mid/max ticks as an RGB image array."""
    lut = colormap_lut(cmap)
    bar_h = 18
    img = Image.new("RGB", (width, height), (255, 255, 255))
    ramp = lut[np.linspace(0, 255, width - 20).astype(int)]
    bar = np.repeat(ramp[None, :, :], bar_h, axis=0)
    img.paste(Image.fromarray(bar), (10, 2))
    draw = ImageDraw.Draw(img)
    font = ImageFont.load_default()
    for frac in (0.0, 0.5, 1.0):
        x = 10 + frac * (width - 21)
        draw.line([(x, 2 + bar_h), (x, 6 + bar_h)], fill=(0, 0, 0))
        text = f"{vmin + frac * (vmax - vmin):.4g}"
        tw = draw.textlength(text, font=font)
        draw.text((min(max(0, x - tw / 2), width - tw), 8 + bar_h), text, fill=(0, 0, 0), font=font)
    return np.asarray(img)


def swatch_html(stats: LayerStats, cmap: str) -> str:
    """Return the legend for the colours that are not on the scale, with their counts."""
    nan_rgb, posinf_rgb, neginf_rgb = SPECIAL_COLORS[cmap]

    def item(rgb: tuple[int, int, int], label: str, count: int) -> str:
        return (
            f'<span style="display:inline-block;width:12px;height:12px;margin-right:4px;'
            f'background:rgb{rgb};border:1px solid #888"></span>{label}: {count}'
        )

    parts = [
        item(nan_rgb, "NaN", stats.n_nan),
        item(posinf_rgb, "+inf", stats.n_posinf),
        item(neginf_rgb, "-inf", stats.n_neginf),
    ]
    return '<div style="font-size:12px;line-height:18px">' + " &nbsp; ".join(parts) + "</div>"


def png_bytes(image: npt.NDArray[np.uint8]) -> bytes:
    """Encode an RGB(A) array as PNG bytes."""
    buf = io.BytesIO()
    Image.fromarray(image).save(buf, format="PNG")
    return buf.getvalue()
