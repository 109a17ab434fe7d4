"""Labels drawn as overlay nodes over the untouched base mesh, re-sent per touched chunk.

Faces are grouped into spatial chunks (Morton order of centroids, ~``CHUNK_FACES`` each). Each
(class, chunk) with labelled faces is one ``add_mesh_simple`` node whose vertices are the
chunk's vertices (bit-identical float32 to the base, no offset, opacity 0.999 so it always
wins the depth tie; see ../shared/research/viser_label_overlays.md). A label edit re-sends only
the ``faces`` of the nodes of the chunks it touched whose faces changed: bytes grow with the
change, not the map.

``CHUNK_FACES`` trades bytes per small edit against node count. A stroke re-sends all faces of
each (class, chunk) it touches, so smaller chunks send less; but creating a node costs viser
~0.4 ms (a 250k-face selection on the 1M-face bench terrain makes ~100 nodes at 4096, ~175 at
2048) and the browser ~11 µs per node per frame. The research found ~4k faces per chunk the
balance; at 1M faces bench measures ~120 B per changed face (1,000-face strokes) at 4096.
"""

from __future__ import annotations

import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np
import numpy.typing as npt
import viser

from storage import (
    ClassAtom,
    DocumentChanged,
    InstanceAtom,
    LabelAtom,
    MapDocument,
)

logger = logging.getLogger(__name__)

CHUNK_FACES = 4096
OVERLAY_ROOT = "/labels"
OVERLAY_OPACITY = 0.999

NodeHook = Callable[[viser.MeshHandle], None]


@dataclass(eq=False)
class Chunk:
    """One spatial run of faces and the vertices they use (remapped to local ids)."""

    face_ids: npt.NDArray[np.int32]  # sorted global face ids
    vertex_ids: npt.NDArray[np.int32]  # global vertex ids used by those faces
    local_faces: npt.NDArray[np.uint32]  # [n, 3] faces in chunk-local vertex ids


def morton_chunks(
    vertices: npt.NDArray[np.float32], faces: npt.NDArray[np.int32], size: int = CHUNK_FACES
) -> tuple[list[Chunk], npt.NDArray[np.int32]]:
    """Split faces into spatially compact chunks; return them and the chunk id of every face."""
    n = len(faces)
    if n == 0:
        return [], np.zeros(0, np.int32)
    centroids = vertices[faces].mean(axis=1, dtype=np.float64)
    lo, hi = centroids.min(axis=0), centroids.max(axis=0)
    q = ((centroids - lo) / np.maximum(hi - lo, 1e-12) * 1023).astype(np.uint64)
    code = np.zeros(n, np.uint64)
    for bit in range(10):
        for axis in range(3):
            code |= ((q[:, axis] >> np.uint64(bit)) & np.uint64(1)) << np.uint64(3 * bit + axis)
    order = np.argsort(code, kind="stable").astype(np.int32)
    chunk_of = np.empty(n, np.int32)
    chunks = []
    for k, start in enumerate(range(0, n, size)):
        ids = np.sort(order[start : start + size])
        chunk_of[ids] = k
        vids, inverse = np.unique(faces[ids], return_inverse=True)
        chunks.append(Chunk(ids, vids.astype(np.int32), inverse.reshape(-1, 3).astype(np.uint32)))
    return chunks, chunk_of


class LabelOverlay:
    """Keeps one node per (class, chunk) in step with the document's labels.

    Document events only mark chunks dirty (they arrive under the document lock); ``flush``
    sends the dirty chunks, from a background flusher or directly in tests and benchmarks.
    """

    def __init__(
        self, server: viser.ViserServer, *, on_node: NodeHook | None = None, autoflush: bool = True
    ) -> None:
        self.server = server
        self.scene = server.scene
        self.on_node = on_node
        self._lock = threading.Lock()  # dirty sets and the chunking
        self._send_lock = threading.Lock()  # the nodes; held while sending
        self._doc: MapDocument | None = None
        self._chunks: list[Chunk] = []
        self._chunk_of = np.zeros(0, np.int32)
        self._nodes: dict[tuple[str, int], viser.MeshHandle] = {}
        self._dirty: set[int] = set()
        self._recolor: set[str] = set()
        self._wake = threading.Event()
        self._stop = threading.Event()
        self._unsubscribe: Callable[[], None] | None = None
        self.visible = True
        self._thread: threading.Thread | None = None
        if autoflush:
            self._thread = threading.Thread(target=self._run, name="label-overlay", daemon=True)
            self._thread.start()

    # ------------------------------------------------------------------ lifecycle
    def show(self, doc: MapDocument) -> None:
        """Draw the labels of ``doc`` (a newly opened map) and follow its changes."""
        chunks, chunk_of = morton_chunks(doc.vertices_local, doc.faces)
        # Lock order everywhere: document lock before ``_lock``; never the other way round.
        if self._unsubscribe is not None:
            self._unsubscribe()
        with self._send_lock:
            for handle in self._nodes.values():
                handle.remove()
            self._nodes.clear()
        with doc.lock:
            with self._lock:
                self._doc = doc
                self._chunks, self._chunk_of = chunks, chunk_of
                self._dirty = set(np.unique(chunk_of[doc.face_labels >= 0]).tolist())
                self._recolor.clear()
            self._unsubscribe = doc.subscribe(self._on_event)
        self._wake.set()

    def close(self) -> None:
        """Stop the flusher thread."""
        self._stop.set()
        self._wake.set()
        if self._thread is not None:
            self._thread.join(timeout=5)

    @property
    def node_count(self) -> int:
        """Return how many overlay nodes exist."""
        return len(self._nodes)

    def handles(self) -> list[viser.MeshHandle]:
        """Return the overlay nodes (tools attach their pointer callbacks to them)."""
        with self._send_lock:
            return list(self._nodes.values())

    def set_visible(self, visible: bool) -> None:
        """Show or hide every label overlay."""
        with self._send_lock:
            self.visible = visible
            for handle in self._nodes.values():
                handle.visible = visible

    # ------------------------------------------------------------------ events
    def _on_event(self, event: object) -> None:
        if not isinstance(event, DocumentChanged):
            return
        atom = event.atom
        with self._lock:
            if isinstance(atom, LabelAtom):
                self._mark_faces(atom.face_ids)
            elif isinstance(atom, InstanceAtom):
                # an instance moved between classes (class rename): its faces change node
                old, new = atom.old, atom.new
                if old is not None and new is not None and old.class_name != new.class_name:
                    self._mark_instance(atom.instance_id)
            elif isinstance(atom, ClassAtom) and atom.old is not None and atom.new is not None:
                self._recolor.add(atom.name)
            # Adding or deleting a class needs nothing here: deleting unlabels its faces first,
            # and those LabelAtoms mark the chunks.
        self._wake.set()

    def _mark_instance(self, iid: int) -> None:
        assert self._doc is not None
        self._mark_faces(np.flatnonzero(self._doc.face_labels == iid))

    def _mark_faces(self, face_ids: npt.NDArray[np.integer]) -> None:
        # bincount, not np.unique: this runs under the document lock, and for a 250k-face
        # edit np.unique costs ~2 ms against ~0.3 ms
        if len(face_ids):
            hit = np.bincount(self._chunk_of[face_ids], minlength=len(self._chunks))
            self._dirty.update(np.flatnonzero(hit).tolist())

    # ------------------------------------------------------------------ sending
    def _run(self) -> None:
        while not self._stop.is_set():
            self._wake.wait()
            self._wake.clear()
            if self._stop.is_set():
                return
            try:
                self.flush()
            except Exception:
                logger.exception("label overlay update failed")

    def flush(self) -> int:
        """Send every dirty chunk now; return how many nodes were created, changed or removed."""
        with self._send_lock:
            with self._lock:
                doc = self._doc
                if doc is None:
                    return 0
                dirty, self._dirty = sorted(self._dirty), set()
                recolor, self._recolor = set(self._recolor), set()
                chunks = self._chunks
            with doc.lock:  # a consistent view of labels and classes
                labels = [doc.face_labels[chunks[k].face_ids] for k in dirty]
                classes = dict(doc.classes)
                class_of = {iid: inst.class_name for iid, inst in doc.instances.items()}
            changed = 0
            with self.server.atomic():
                for k, chunk_labels in zip(dirty, labels, strict=True):
                    changed += self._send_chunk(doc, chunks[k], k, chunk_labels, classes, class_of)
                for (name, _), handle in self._nodes.items():
                    if name in recolor and name in classes:
                        handle.color = classes[name].color
                        changed += 1
            return changed

    def _send_chunk(
        self,
        doc: MapDocument,
        chunk: Chunk,
        k: int,
        chunk_labels: npt.NDArray[np.int32],
        classes: dict,
        class_of: dict[int, str],
    ) -> int:
        present: dict[str, npt.NDArray[np.bool_]] = {}
        for iid in np.unique(chunk_labels):
            name = class_of.get(int(iid), "")
            if iid < 0 or not name:
                continue
            mask = chunk_labels == iid
            present[name] = present[name] | mask if name in present else mask
        changed = 0
        for key in [key for key in self._nodes if key[1] == k and key[0] not in present]:
            self._nodes.pop(key).remove()
            changed += 1
        for name, mask in present.items():
            faces = chunk.local_faces[mask]
            handle = self._nodes.get((name, k))
            if handle is None:
                handle = self.scene.add_mesh_simple(
                    f"{OVERLAY_ROOT}/{_safe(name)}/{k}",
                    doc.vertices_local[chunk.vertex_ids],
                    faces,
                    color=classes[name].color,
                    opacity=OVERLAY_OPACITY,
                    flat_shading=True,
                    side="double",
                    cast_shadow=False,
                    receive_shadow=False,
                    visible=self.visible,
                )
                self._nodes[(name, k)] = handle
                if self.on_node is not None:
                    self.on_node(handle)
            elif not np.array_equal(faces, handle.faces):
                handle.faces = faces  # viser sends this prop alone
            else:
                # dirty for another class's sake; viser would drop the equal array too, but
                # this keeps ``flush``'s count of changed nodes true
                continue
            changed += 1
        return changed


def _safe(name: str) -> str:
    return "".join(ch if ch.isalnum() or ch in "-." else f"%{ord(ch):02x}" for ch in name)
