"""Open and save maps: the suffix -> reader registry, ``load_map`` and ``save_map``.

Each format module exports a small ``{suffix: reader}`` dict (trimesh's loader registry
shape); this module merges them. Whatever goes wrong while reading reaches the caller as a
``MapFormatError`` naming the file, never as a raw h5py, trimesh or numpy exception.
"""

from __future__ import annotations

import logging
from collections.abc import Callable
from pathlib import Path

from storage import hdf5_read, mesh_read
from storage.document import MapDocument
from storage.errors import MapFormatError
from storage.hdf5_write import write_hdf5
from storage.model import MapData

logger = logging.getLogger(__name__)

Reader = Callable[[Path], MapData]

#: suffix (lower case, with the dot) -> reader
READERS: dict[str, Reader] = {**hdf5_read.READERS, **mesh_read.READERS}
#: suffixes ``save_map`` writes (HDF5 only: mesh_navigation needs an .h5 working file)
WRITE_SUFFIXES = (".h5", ".hdf5")
_HDF5_SIGNATURE = b"\x89HDF\r\n\x1a\n"
#: Signatures of files people mistake for meshes: refused with a message saying what they are.
_NOT_MESHES = {
    b"\x89PNG\r\n\x1a\n": "a PNG image",
    b"\xff\xd8\xff": "a JPEG image",
    b"GIF8": "a GIF image",
    b"%PDF": "a PDF document",
    b"PK\x03\x04": "a ZIP archive",
}


def read_map_data(path: str | Path) -> MapData:
    """Read any supported file into ``MapData`` (the reader chosen by suffix, or content).

    Raises
    ------
    MapFormatError
        For a missing file, a folder, an unknown suffix, or a file that cannot be read as a
        mesh map; the message names the file and the problem.
    """
    path = Path(path)
    reader = _reader_for(path)
    try:
        data = reader(path)
    except MapFormatError:
        raise
    except MemoryError as exc:
        raise MapFormatError(path, "is too large to load into memory") from exc
    except Exception as exc:
        logger.debug("reading %s failed", path, exc_info=True)
        raise MapFormatError(path, _explain(path, exc)) from exc
    for warning in data.warnings:
        logger.info("%s: %s", path.name, warning)
    return data


def load_map(path: str | Path) -> MapDocument:
    """Open a map file as a ``MapDocument`` (the file is closed again before this returns).

    Raises
    ------
    MapFormatError
        See ``read_map_data``.
    """
    return MapDocument(read_map_data(path), Path(path))


def save_map(
    doc_or_data: MapDocument | MapData,
    path: str | Path,
    *,
    compression: str | None = "gzip",
) -> list[str]:
    """Save a document (a consistent snapshot of it) or plain ``MapData`` as an HDF5 map.

    Writes the current layout (``storage.hdf5_write``) atomically: a failure leaves any file
    at ``path`` as it was. Saving over the file the document was loaded from is fine.

    Parameters
    ----------
    compression : "gzip" (level ``hdf5_write.GZIP_LEVEL``, with shuffle) or None

    Returns
    -------
    list of str
        Notes worth showing the user (how lvr2 / mesh_navigation / RViz will see the file).

    Raises
    ------
    MapFormatError
        When the target cannot be written or is not an .h5 name.
    """
    path = Path(path)
    if path.suffix.lower() not in WRITE_SUFFIXES:
        raise MapFormatError(
            path, f"meshmark saves HDF5 maps only; use a name ending in {WRITE_SUFFIXES[0]}"
        )
    data = doc_or_data.snapshot() if isinstance(doc_or_data, MapDocument) else doc_or_data
    return write_hdf5(data, path, compression=compression)


def _reader_for(path: Path) -> Reader:
    if not path.exists():
        raise MapFormatError(path, "no such file")
    if path.is_dir():
        raise MapFormatError(path, "is a folder, not a map file")
    try:
        with open(path, "rb") as fh:
            head = fh.read(8)
    except OSError as exc:
        raise MapFormatError(path, f"cannot be opened: {exc.strerror or exc}") from exc
    if head == _HDF5_SIGNATURE:  # an HDF5 map under another name is still a map
        return hdf5_read.read_hdf5
    reader = READERS.get(path.suffix.lower())
    if reader is None:
        known = " ".join(sorted(READERS))
        what = f"'{path.suffix}'" if path.suffix else "without a suffix"
        raise MapFormatError(path, f"unknown file type {what}; meshmark reads {known}")
    if not head:
        raise MapFormatError(path, "the file is empty")
    for signature, what in _NOT_MESHES.items():
        if head.startswith(signature):
            raise MapFormatError(path, f"is {what}, not a mesh map")
    return reader


def _explain(path: Path, exc: Exception) -> str:
    """Say in the user's words why a reader failed (the raw error stays in the debug log)."""
    kind = path.suffix.lower().lstrip(".").upper() or "map"
    if isinstance(exc, IndexError):
        return f"not a valid {kind} file: a face refers to a vertex that does not exist ({exc})"
    if isinstance(exc, UnicodeDecodeError):
        return f"not a valid {kind} file: it holds bytes that are not text where text belongs"
    if isinstance(exc, OSError):
        return f"cannot be read: {exc.strerror or exc}"
    text = str(exc).strip() or type(exc).__name__
    return f"not a valid {kind} file ({text})"
