"""The per-geometry selection structures (Embree index, rect selector, face adjacency).

Built once per opened map on the job thread, so the browser stays usable while a big map is
indexed; until then the tools say "indexing…" instead of blocking.
"""

from __future__ import annotations

import logging
import threading
import time
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt

from geometry import face_adjacency
from selection import BrushIndex, MeshIndex, RectSelector, brush_faces
from storage import MapDocument

logger = logging.getLogger(__name__)


@dataclass(frozen=True, eq=False)
class Picking:
    """Everything the tools query for one geometry; immutable, shared by all threads."""

    doc: MapDocument
    index: MeshIndex
    rect: RectSelector
    brushes: BrushIndex
    build_s: float

    def brush(
        self,
        points_world: npt.ArrayLike,
        seed_faces: npt.ArrayLike,
        radius: float,
        connected: bool,
    ) -> npt.NDArray[np.int32]:
        """Return the faces brush dabs of ``radius`` at ``points_world`` ([k, 3]) cover."""
        return brush_faces(
            self.brushes, points_world, radius, seed_face=seed_faces, connected=connected
        )


def build_picking(doc: MapDocument) -> Picking:
    """Build the index, the rect selector and the adjacency for ``doc`` (seconds at 1M faces)."""
    t0 = time.perf_counter()
    index = MeshIndex(doc.vertices, doc.faces, origin=doc.origin)
    rect = RectSelector(doc.vertices_local, doc.faces)
    brushes = BrushIndex(doc.vertices, doc.faces, adjacency=face_adjacency(doc.faces))
    picking = Picking(doc, index, rect, brushes, 0.0)
    if doc.n_faces:  # compile and warm the kernels now, not on the first click
        picking.brush(doc.vertices[doc.faces[0]].mean(axis=0), 0, 1e-6, True)
    return Picking(doc, index, rect, brushes, time.perf_counter() - t0)


class PickingSlot:
    """Holds the ``Picking`` of the open map once it is ready (swapped when a map opens)."""

    def __init__(self) -> None:
        self._lock = threading.Lock()
        self._value: Picking | None = None

    def get(self, doc: MapDocument) -> Picking | None:
        """Return the structures for ``doc``, or None while they are being built."""
        with self._lock:
            value = self._value
        return value if value is not None and value.doc is doc else None

    def set(self, value: Picking | None) -> None:
        """Publish newly built structures (or clear them)."""
        with self._lock:
            self._value = value
