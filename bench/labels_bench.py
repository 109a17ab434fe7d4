"""Labels: applying a large selection, and the bytes a small edit sends to the browser (issue 4).

Everything runs against a real ``viser.ViserServer`` (port 0, no client) and a
``LabelOverlay(server, autoflush=False)`` whose ``flush()`` is called here, so the time of
building the overlay nodes is attributed to the edit that caused it.

Keys (1M faces in the reference run):

- ``label_apply_ms``: label a 250k-face selection (the faces whose centroids lie nearest to a
  point, i.e. a disc of the terrain, crossing a wall and a step) with one instance inside a
  gesture, then ``flush()``: the overlay nodes for those faces are created and queued with
  viser. Median of ``args.repeats`` after a warm-up; ``doc.undo()`` + ``flush()`` (untimed)
  between repeats so that each repeat does the same work. ``label_apply_bytes`` is what viser
  serialises for that edit, ``label_apply_serialize_ms`` the time the serialisation takes
  (done by viser's producer per connected client; not part of ``label_apply_ms``).
  ``label_apply_cpu_ms`` is the process CPU time of the same repeats: on a busy 2-core machine
  the wall time jumps when other processes take the CPU, the CPU time much less.
- ``label_update_bytes_per_face``: a class holding a compact 200k-face region (created and
  flushed first), then 20 strokes around its border; each stroke labels the 1,000 unlabelled
  faces nearest to a point on the border with the same instance and flushes. Every message
  queued with viser during the flush is captured and serialised exactly as viser's websocket
  producer does (``wire_bytes``); bytes over faces changed, mean over the strokes.
  ``label_update_bytes_max`` is the largest stroke; ``label_update_nodes_touched_mean`` the
  overlay nodes a stroke created, changed or removed; ``label_nodes`` the overlay node count
  after the strokes.
"""

from __future__ import annotations

import contextlib
import math
import statistics
import time
from collections.abc import Iterator

import msgspec
import numpy as np
import viser
import zstandard
from viser.infra._infra import _append_aligned_buffers
from viser.infra._messages import Message

from app.label_overlay import LabelOverlay
from bench.terrain import Terrain
from storage import MapData, MapDocument

APPLY_FACES = 250_000
APPLY_CENTRE = (-20.0, 10.0)  # world xy; the disc crosses the wall at x=-50 and the step at 30
REGION_FACES = 200_000
REGION_CENTRE = (25.0, -15.0)
STROKES = 20
STROKE_FACES = 1_000


@contextlib.contextmanager
def captured_messages(server: viser.ViserServer) -> Iterator[list[Message]]:
    """Collect every message queued with the server's broadcast websocket inside the block."""
    ws = server._websock_server
    messages: list[Message] = []
    original = ws.queue_message
    shadowed = "queue_message" in vars(ws)

    def queue_message(message: Message) -> None:
        messages.append(message)
        original(message)

    ws.queue_message = queue_message  # type: ignore[method-assign]
    try:
        yield messages
    finally:
        if shadowed:
            ws.queue_message = original  # type: ignore[method-assign]
        else:
            del ws.queue_message  # back to the class's method


def wire_bytes(messages: list[Message], *, window: int = 128) -> int:
    """Bytes viser 1.1.1's ``_message_producer`` sends for ``messages``.

    Same steps as the producer: windows of at most ``AsyncMessageBuffer.max_window_size``
    messages (a flush inside ``server.atomic()`` is released at once, so the windows are
    full); per window, numpy arrays go to raw binary buffers, the rest to msgpack,
    zstd level 1; header of two uint64, buffers 8-byte aligned.
    """
    zstd = zstandard.ZstdCompressor(level=1)
    total = 0
    for start in range(0, len(messages), window):
        binary: list[memoryview] = []
        serialized = tuple(m.as_serializable_dict(binary) for m in messages[start : start + window])
        inner = msgspec.msgpack.encode(
            {
                "messages": serialized,
                "timestampSec": time.perf_counter(),
                "binaryBufferLengths": tuple(b.nbytes for b in binary),
            }
        )
        compressed = zstd.compress(inner)
        parts: list[bytes | memoryview] = [
            len(inner).to_bytes(8, "little"),
            len(compressed).to_bytes(8, "little"),
            compressed,
        ]
        _append_aligned_buffers(parts, binary, 16 + len(compressed))
        total += sum(p.nbytes if isinstance(p, memoryview) else len(p) for p in parts)
    return total


def nearest(centroids: np.ndarray, point: tuple[float, float], count: int) -> np.ndarray:
    """Ids of the ``count`` rows of ``centroids`` (xy) nearest to ``point``, sorted."""
    d2 = ((centroids - np.asarray(point)) ** 2).sum(axis=1)
    return np.sort(np.argpartition(d2, count - 1)[:count]).astype(np.int32)


def run(terrain: Terrain, args) -> dict:
    repeats = max(int(args.repeats), 1)
    out: dict[str, object] = {}
    centroids = terrain.vertices[terrain.faces].mean(axis=1)[:, :2]
    server = viser.ViserServer(host="127.0.0.1", port=0, verbose=False)
    try:
        out.update(_apply(terrain, server, centroids, repeats))
        out.update(_strokes(terrain, server, centroids))
    finally:
        server.stop()
    return out


def _apply(terrain: Terrain, server: viser.ViserServer, centroids: np.ndarray, repeats: int):
    doc = MapDocument(MapData(terrain.vertices, terrain.faces))
    overlay = LabelOverlay(server, autoflush=False)
    try:
        overlay.show(doc)
        overlay.flush()
        doc.add_class("apply", (220, 40, 40))
        iid = doc.add_instance("apply", "1")
        selection = nearest(centroids, APPLY_CENTRE, min(APPLY_FACES, terrain.n_faces // 4))

        def apply() -> None:
            with doc.gesture():
                doc.label_faces(selection, iid)
            overlay.flush()

        def undo() -> None:
            assert doc.undo()
            overlay.flush()
            assert overlay.node_count == 0

        apply(), undo()  # warm-up
        samples, cpu = [], []
        for _ in range(repeats):
            c0, t0 = time.process_time(), time.perf_counter()
            apply()
            samples.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
            undo()
        with captured_messages(server) as messages:
            apply()
        nodes = overlay.node_count
        t0 = time.perf_counter()
        size = wire_bytes(messages)
        serialize_s = time.perf_counter() - t0
        undo()
    finally:
        overlay.close()
    return {
        "label_apply_ms": statistics.median(samples) * 1e3,
        "label_apply_cpu_ms": statistics.median(cpu) * 1e3,
        "label_apply_nodes": nodes,
        "label_apply_bytes": size,
        "label_apply_serialize_ms": serialize_s * 1e3,
    }


def _strokes(terrain: Terrain, server: viser.ViserServer, centroids: np.ndarray):
    doc = MapDocument(MapData(terrain.vertices, terrain.faces))
    overlay = LabelOverlay(server, autoflush=False)
    try:
        overlay.show(doc)
        overlay.flush()
        doc.add_class("region", (40, 160, 40))
        iid = doc.add_instance("region", "1")
        region = nearest(centroids, REGION_CENTRE, min(REGION_FACES, terrain.n_faces // 4))
        with doc.gesture():
            doc.label_faces(region, iid)
        overlay.flush()
        radius = math.sqrt(((centroids[region] - REGION_CENTRE) ** 2).sum(axis=1).max())
        per_face, sizes, touched = [], [], []
        for i in range(STROKES):
            angle = 2 * math.pi * (i + 0.5) / STROKES
            border = (
                REGION_CENTRE[0] + radius * math.cos(angle),
                REGION_CENTRE[1] + radius * math.sin(angle),
            )
            free = np.flatnonzero(doc.face_labels < 0)
            stroke = free[nearest(centroids[free], border, STROKE_FACES)]
            with doc.gesture():
                atom = doc.label_faces(stroke, iid)
            assert atom is not None
            with captured_messages(server) as messages:
                touched.append(overlay.flush())
            size = wire_bytes(messages)
            sizes.append(size)
            per_face.append(size / len(atom.face_ids))
        nodes = overlay.node_count
    finally:
        overlay.close()
    return {
        "label_update_bytes_per_face": statistics.fmean(per_face),
        "label_update_bytes_max": max(sizes),
        "label_update_nodes_touched_mean": statistics.fmean(touched),
        "label_nodes": nodes,
    }
