"""The local frame: a float64 origin subtracted before anything is cast to float32."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt

#: Coordinates whose bounding box stays within this distance of 0 are kept as they are.
NEAR_ORIGIN_M = 10_000.0
#: Far-away origins are rounded to this step, so they stay readable (e.g. whole kilometres).
ORIGIN_STEP_M = 1_000.0


def local_origin(vertices: npt.NDArray[np.floating]) -> npt.NDArray[np.float64]:
    """Return a float64 origin that keeps float32 precision for far-away (UTM-like) coordinates.

    Zero when the bounding box lies near the origin; otherwise the box centre rounded to
    ``ORIGIN_STEP_M`` so that ``vertices - origin`` is small and float32 keeps millimetres.

    Returns
    -------
    float64 [3]
    """
    v = np.asarray(vertices, dtype=np.float64)
    finite = v[np.isfinite(v).all(axis=1)] if len(v) else v
    if len(finite) == 0:
        return np.zeros(3)
    lo, hi = finite.min(axis=0), finite.max(axis=0)
    if max(np.abs(lo).max(), np.abs(hi).max()) <= NEAR_ORIGIN_M:
        return np.zeros(3)
    return np.round((lo + hi) / 2.0 / ORIGIN_STEP_M) * ORIGIN_STEP_M
