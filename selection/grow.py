"""Region growing: the faces connected to a seed face, optionally inside a mask."""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import scipy.sparse as sp

from selection._kernels import flood


def flood_faces(
    adjacency: sp.spmatrix | sp.sparray,
    seed_face: int,
    *,
    within: npt.ArrayLike | None = None,
) -> npt.NDArray[np.int32]:
    """Return the faces reachable from ``seed_face`` across shared edges (a flood fill).

    Parameters
    ----------
    adjacency : scipy.sparse matrix [F, F]
        Face adjacency, e.g. ``geometry.face_adjacency(faces)``; any nonzero entry links two
        faces.
    seed_face : int
        Where the fill starts.
    within : bool [F], optional
        Faces the fill may enter; None: all faces. A seed outside it gives an empty result.

    Returns
    -------
    int32 [m]
        Face ids, ascending, including the seed.

    Notes
    -----
    Writing the result into labels is the document's job; this only answers which faces.

    Examples
    --------
    >>> import scipy.sparse as sp
    >>> chain = sp.csr_matrix(([1, 1, 1, 1], ([0, 1, 1, 2], [1, 0, 2, 1])), shape=(4, 4))
    >>> flood_faces(chain, 0).tolist()
    [0, 1, 2]
    >>> flood_faces(chain, 0, within=[True, True, False, True]).tolist()
    [0, 1]
    """
    csr = sp.csr_matrix(adjacency)
    n = csr.shape[0]
    if csr.shape != (n, n):
        raise ValueError(f"adjacency must be square, got {csr.shape}")
    seed = int(seed_face)
    if not 0 <= seed < n:
        raise ValueError(f"seed face {seed} does not exist ({n} faces)")
    if within is None:
        mask = np.zeros(0, np.bool_)
    else:
        mask = np.ascontiguousarray(within, dtype=np.bool_)
        if mask.shape != (n,):
            raise ValueError(f"within must be a bool mask of shape ({n},), got {mask.shape}")
    csr.eliminate_zeros()
    ids = flood(csr.indptr.astype(np.int64), csr.indices.astype(np.int32), seed, mask)
    ids.sort()
    return ids
