"""Mesh maps in memory and on disk: ``MapDocument``, readers for every layout, the HDF5 writer."""

from storage.document import MapDocument
from storage.errors import DocumentError, LabelNameError, MapFormatError, MeshmarkError
from storage.events import DocumentChanged, DocumentSaved
from storage.history import ClassAtom, GoalsAtom, InstanceAtom, LabelAtom, LayerAtom
from storage.model import UNLABELLED, Goal, Instance, LabelClass, MapData, Texture
from storage.names import check_name, name_problem

__all__ = [
    "UNLABELLED",
    "ClassAtom",
    "DocumentChanged",
    "DocumentError",
    "DocumentSaved",
    "Goal",
    "GoalsAtom",
    "Instance",
    "InstanceAtom",
    "LabelAtom",
    "LabelClass",
    "LabelNameError",
    "LayerAtom",
    "MapData",
    "MapDocument",
    "MapFormatError",
    "MeshmarkError",
    "Texture",
    "check_name",
    "name_problem",
]
