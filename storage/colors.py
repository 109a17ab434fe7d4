"""Colours as meshmark keeps them: uint8 RGB per vertex, and a palette for new label classes."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: Colours given to label classes that arrive without one (Okabe-Ito, colour-blind safe).
CLASS_PALETTE: tuple[tuple[int, int, int], ...] = (
    (230, 159, 0),
    (86, 180, 233),
    (0, 158, 115),
    (240, 228, 66),
    (0, 114, 178),
    (213, 94, 0),
    (204, 121, 167),
    (153, 153, 153),
)
#: What a NaN colour is shown as.
NAN_GREY = 128


def class_color(index: int) -> tuple[int, int, int]:
    """Return the palette colour for the ``index``-th class (cycling)."""
    return CLASS_PALETTE[index % len(CLASS_PALETTE)]


def colors_to_uint8(
    values: npt.ArrayLike, n: int, warnings: list[str], *, where: str
) -> npt.NDArray[np.uint8] | None:
    """Turn stored colours (uint8 or 0..1 floats, RGB or RGBA, flat or [N, k]) into uint8 [N, 3].

    NaN colours become grey with a warning; a shape that fits no per-vertex colour is
    skipped with a warning (None). Alpha is dropped: maps are opaque.
    """
    a = np.asarray(values)
    if a.ndim == 1 and n and a.size in (3 * n, 4 * n):
        a = a.reshape(n, -1)
    if a.ndim != 2 or a.shape[0] != n or a.shape[1] not in (3, 4) or a.dtype.kind not in "fiub":
        warnings.append(f"{where} {a.shape} {a.dtype} is not one RGB colour per vertex; ignored")
        return None
    rgb = a[:, :3]
    if rgb.dtype == np.uint8:
        return np.ascontiguousarray(rgb)
    rgb = rgb.astype(np.float64)
    bad = np.isnan(rgb).any(axis=1)
    if a.dtype.kind == "f" and np.nanmax(rgb, initial=0.0) <= 1.0:
        rgb = rgb * 255.0
    out = np.clip(np.rint(np.nan_to_num(rgb, nan=NAN_GREY)), 0, 255).astype(np.uint8)
    if bad.any():
        out[bad] = NAN_GREY
        warnings.append(nan_color_warning(int(bad.sum())))
    return out


def nan_color_warning(count: int) -> str:
    """Say that ``count`` NaN colours were replaced (one wording for every reader)."""
    return (
        f"{count:,} vertex colour(s) were NaN in the file; replaced with grey "
        f"({NAN_GREY}, {NAN_GREY}, {NAN_GREY})"
    )
