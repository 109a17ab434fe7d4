"""The one error hierarchy of meshmark's data layer: messages are written for the user."""

from __future__ import annotations

from pathlib import Path


class MeshmarkError(Exception):
    """Base of every error whose message can be shown to the user as it is."""


class MapFormatError(MeshmarkError):
    """A file cannot be read (or written) as a mesh map; names the file and the problem."""

    def __init__(self, path: str | Path, problem: str) -> None:
        self.path = Path(path)
        self.problem = problem
        super().__init__(f"{self.path.name}: {problem}")


class LabelNameError(MeshmarkError, ValueError):
    """A class or instance name breaks the ``<class>_<instance>`` rule of mesh_tools."""


class DocumentError(MeshmarkError):
    """An edit refers to something the document does not hold (unknown class, bad face id...)."""
