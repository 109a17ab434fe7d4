"""Files meshmark ships as package data: the demo map, its licence, colormaps."""

from __future__ import annotations

import atexit
import contextlib
from importlib import resources
from pathlib import Path

#: The floor_is_lava tutorial world (BSD-3-Clause, Nature Robots) in the current HDF5 layout.
DEMO_MAP = "demo_floor_is_lava.h5"

_extracted = contextlib.ExitStack()
atexit.register(_extracted.close)


def demo_map_path() -> Path:
    """Return a real file path of the demo map, wherever the package is installed.

    An ordinary install gives the file inside the package; a zipped one extracts it once
    to a temporary file that lives until the interpreter exits.
    """
    resource = resources.files(__name__) / DEMO_MAP
    if isinstance(resource, Path):
        return resource
    return _extracted.enter_context(resources.as_file(resource))
