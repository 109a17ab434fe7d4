"""What a mesh map holds, as plain immutable values: the file-level data model.

``MapData`` is what readers produce and writers consume; ``MapDocument`` wraps one with a
lock, history and change events. Arrays are in the file's own (world) frame.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any

import numpy as np
import numpy.typing as npt

UNLABELLED = -1


@dataclass(frozen=True)
class LabelClass:
    """A label class such as ``stairs``: a name and a display colour (RGB 0..255)."""

    name: str
    color: tuple[int, int, int]


@dataclass(frozen=True)
class Instance:
    """One instance of a class (``grass`` / ``1``); saved as ``/mesh/labels/<class>/<name>``."""

    class_name: str
    name: str

    @property
    def full_name(self) -> str:
        """Return the name mesh_tools shows: ``<class>_<instance>``."""
        return f"{self.class_name}_{self.name}"


@dataclass(frozen=True)
class Goal:
    """A 6-D goal pose on the surface (world frame of the file, quaternion x, y, z, w)."""

    name: str
    position: tuple[float, float, float]
    orientation_xyzw: tuple[float, float, float, float]
    frame_id: str = "map"


@dataclass(frozen=True, eq=False)
class Texture:
    """A texture image with per-vertex UVs (OBJ/trimesh convention: v = 0 at the image bottom).

    That is what trimesh's ``TextureVisuals`` takes (its glTF exporter flips v itself), what
    OBJ files store, and what readers produce for every format.
    """

    uv: npt.NDArray[np.float32]  #: [N, 2] per-vertex texture coordinates
    image: bytes  #: the encoded image file (PNG or JPEG), kept byte-exact
    mime_type: str = "image/png"


@dataclass(eq=False)
class MapData:
    """Everything a mesh map file holds, in the file's frame.

    Parameters
    ----------
    vertices : float64 [N, 3], world coordinates as in the file (origin already added back)
    faces : int32 [F, 3], vertex ids; face order is the file's and defines face ids
    layers : name -> float32 [N]; NaN = unknown, +inf = lethal, kept as data
    vertex_colors : uint8 [N, 3] or None
    texture : Texture or None
    face_labels : int32 [F], instance id per face, -1 = unlabelled
    classes : name -> LabelClass, in display order
    instances : instance id -> Instance
    goals : goal poses in list order
    meta : free-form facts about the source (``layout``, ``format``, ``origin``...)
    warnings : what was repaired or skipped while reading, for the user
    """

    vertices: npt.NDArray[np.float64]
    faces: npt.NDArray[np.int32]
    layers: dict[str, npt.NDArray[np.float32]] = field(default_factory=dict)
    vertex_colors: npt.NDArray[np.uint8] | None = None
    texture: Texture | None = None
    face_labels: npt.NDArray[np.int32] | None = None
    classes: dict[str, LabelClass] = field(default_factory=dict)
    instances: dict[int, Instance] = field(default_factory=dict)
    goals: list[Goal] = field(default_factory=list)
    meta: dict[str, Any] = field(default_factory=dict)
    warnings: list[str] = field(default_factory=list)

    def __post_init__(self) -> None:
        self.vertices = np.ascontiguousarray(self.vertices, dtype=np.float64).reshape(-1, 3)
        self.faces = np.ascontiguousarray(self.faces, dtype=np.int32).reshape(-1, 3)
        self.layers = {
            k: np.ascontiguousarray(v, dtype=np.float32).reshape(-1) for k, v in self.layers.items()
        }
        if self.face_labels is None:
            self.face_labels = np.full(len(self.faces), UNLABELLED, dtype=np.int32)
        else:
            self.face_labels = np.ascontiguousarray(self.face_labels, dtype=np.int32)

    @property
    def n_vertices(self) -> int:
        """Return the vertex count."""
        return len(self.vertices)

    @property
    def n_faces(self) -> int:
        """Return the face count."""
        return len(self.faces)
