"""Change events a ``MapDocument`` emits, under its lock, to the view and other listeners."""

from __future__ import annotations

from dataclasses import dataclass

from storage.history import Atom


@dataclass(frozen=True)
class DocumentChanged:
    """One atom was written to the document (``undo`` True when it was an undo/redo replay)."""

    atom: Atom
    replay: bool = False


@dataclass(frozen=True)
class DocumentSaved:
    """The document was written to ``path``; it is no longer dirty."""

    path: str
