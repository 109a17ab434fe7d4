"""What every reader checks before it hands out geometry: the faults no map can carry.

A map is refused when it has no faces, when a face names a vertex that does not exist, or
when a vertex used by a face has NaN or infinite coordinates (nothing can be drawn, picked or
planned on such a face). Non-finite *unused* vertices are kept, because per-vertex layers
index every vertex; the reader says so in a warning.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import numpy.typing as npt

from storage.errors import MapFormatError


def check_geometry(
    path: str | Path,
    vertices: npt.NDArray[np.floating],
    faces: npt.NDArray[np.integer],
    warnings: list[str],
) -> None:
    """Raise ``MapFormatError`` for geometry no tool can use; append warnings for odd parts.

    Parameters
    ----------
    path : the file, named in the error message
    vertices : float [N, 3]
    faces : any integer dtype [F, 3], vertex ids as stored (not yet cast)
    warnings : the reader's warning list, appended to
    """
    n, f = len(vertices), len(faces)
    if f == 0:
        if n == 0:
            raise MapFormatError(path, "the mesh is empty: no vertices and no faces")
        raise MapFormatError(path, f"the mesh has {n:,} vertices but no faces (a point cloud?)")
    if n == 0:
        raise MapFormatError(path, f"the mesh has {f:,} faces but no vertices")
    if n > np.iinfo(np.int32).max:
        raise MapFormatError(path, f"the mesh has {n:,} vertices, more than meshmark can index")
    lo, hi = int(faces.min()), int(faces.max())
    if lo < 0 or hi >= n:
        bad = np.flatnonzero(((faces < 0) | (faces >= n)).any(axis=1))
        first = int(bad[0])
        raise MapFormatError(
            path,
            f"face {first} refers to vertex {faces[first].tolist()}, but the mesh has only "
            f"{n:,} vertices (ids 0..{n - 1}); {len(bad):,} face(s) are out of range",
        )
    finite = np.isfinite(vertices).all(axis=1)
    if finite.all():
        return
    used = np.zeros(n, dtype=bool)
    used[faces.ravel()] = True
    bad_used = np.flatnonzero(~finite & used)
    if len(bad_used):
        v = int(bad_used[0])
        face = int(np.flatnonzero((faces == v).any(axis=1))[0])
        raise MapFormatError(
            path,
            f"vertex {v}, used by face {face}, has non-finite coordinates "
            f"{vertices[v].tolist()}; {len(bad_used):,} vertices used by faces are not finite",
        )
    warnings.append(
        f"{int((~finite).sum()):,} vertices that no face uses have NaN or infinite "
        "coordinates; kept so that per-vertex layers stay aligned"
    )
