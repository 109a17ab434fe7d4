"""Mesh maps in memory and on disk: ``MapDocument``, readers for every layout, the HDF5 writer."""

from storage.document import MapDocument
from storage.errors import DocumentError, LabelNameError, MapFormatError, MeshmarkError
from storage.events import DocumentChanged, DocumentSaved
from storage.goals_io import (
    goal_problem,
    goals_from_json,
    goals_from_yaml,
    goals_to_json,
    goals_to_yaml,
)
from storage.history import ClassAtom, GoalsAtom, InstanceAtom, LabelAtom, LayerAtom
from storage.inspect import ClassStats, LayerStats, MapInfo, inspect_map
from storage.io import READERS, load_map, read_map_data, save_map
from storage.label_export import (
    UNLABELLED_COLOR,
    label_arrays,
    label_files_bytes,
    label_instance_ids,
    ply_with_face_colors,
    write_label_files,
    write_ply_with_face_colors,
)
from storage.model import UNLABELLED, Goal, Instance, LabelClass, MapData, Texture
from storage.names import check_name, name_problem

__all__ = [
    "READERS",
    "UNLABELLED",
    "UNLABELLED_COLOR",
    "ClassAtom",
    "ClassStats",
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
    "LayerStats",
    "MapData",
    "MapDocument",
    "MapFormatError",
    "MapInfo",
    "MeshmarkError",
    "Texture",
    "check_name",
    "goal_problem",
    "goals_from_json",
    "goals_from_yaml",
    "goals_to_json",
    "goals_to_yaml",
    "inspect_map",
    "label_arrays",
    "label_files_bytes",
    "label_instance_ids",
    "load_map",
    "name_problem",
    "ply_with_face_colors",
    "read_map_data",
    "save_map",
    "write_label_files",
    "write_ply_with_face_colors",
]
