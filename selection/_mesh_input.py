"""The one check every selection structure runs on the mesh it is built from."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt


def mesh_arrays(
    vertices: npt.ArrayLike, faces: npt.ArrayLike
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.int32]]:
    """Return C-contiguous float64 [N, 3] vertices and int32 [F, 3] faces, or raise ValueError."""
    v = np.ascontiguousarray(vertices, dtype=np.float64)
    f = np.ascontiguousarray(faces, dtype=np.int32)
    if v.ndim != 2 or v.shape[1] != 3:
        raise ValueError(f"vertices must have shape (N, 3), got {v.shape}")
    if f.ndim != 2 or f.shape[1] != 3:
        raise ValueError(f"faces must have shape (F, 3), got {f.shape}")
    if len(f) and (f.min() < 0 or f.max() >= len(v)):
        raise ValueError("faces refer to vertices that do not exist")
    return v, f
