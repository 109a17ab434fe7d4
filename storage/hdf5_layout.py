"""The names of the current HDF5 map layout, shared by the writer, the reader and the tests.

lvr2 >= 25.1, mesh_navigation and the mesh_tools map display read the part ``/mesh`` only
(research notes §1); what only meshmark understands lives under ``/meshmark`` where they
never look.
"""

from __future__ import annotations

#: The mesh part; the RViz map display hard-codes this name.
PART = "mesh"
GEOMETRY = f"{PART}/geometry"
VERTEX_ATTRIBUTES = f"{PART}/vertex_attributes"
FACE_ATTRIBUTES = f"{PART}/face_attributes"
LABELS = f"{PART}/labels"

#: Attributes lvr2's ``MeshIO::load`` checks on the part group (scalar vlen UTF-8 strings).
PART_ATTRS = {"IO": "MeshIO", "CLASS": "MeshBuffer"}
#: Root ``/version``: scalar int32, written by lvr2 when it creates a file.
VERSION = 1

#: meshmark's own group: origin, class colours, instances, goals, texture image.
MESHMARK = "meshmark"
ORIGIN = f"{MESHMARK}/origin"
CLASS_NAMES = f"{MESHMARK}/classes/names"
CLASS_COLORS = f"{MESHMARK}/classes/colors"
INSTANCE_IDS = f"{MESHMARK}/instances/ids"
INSTANCE_CLASSES = f"{MESHMARK}/instances/classes"
INSTANCE_NAMES = f"{MESHMARK}/instances/names"
GOAL_NAMES = f"{MESHMARK}/goals/names"
GOAL_FRAME_IDS = f"{MESHMARK}/goals/frame_ids"
GOAL_POSITIONS = f"{MESHMARK}/goals/positions"
GOAL_ORIENTATIONS = f"{MESHMARK}/goals/orientations_xyzw"
TEXTURE = f"{MESHMARK}/texture"
LAYER_NAMES = f"{MESHMARK}/layer_names"
#: meshmark's settings (layer parameters, class costs, display choices) as one JSON string.
SETTINGS = f"{MESHMARK}/settings"
#: Version of the ``/meshmark`` group's own schema (attribute ``format_version``).
MESHMARK_FORMAT_VERSION = 1

#: Per-vertex datasets that are geometry, not cost layers; a layer may not take these names.
RESERVED_VERTEX_NAMES = frozenset(
    {"vertex_normals", "vertex_colors", "vertices", "texture_coordinates", "normals", "rgb_colors"}
)
