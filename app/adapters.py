"""The one place where viser's events and camera become meshmark's boundary types.

viser reports rays and cameras in the scene frame, which is the document's local frame
(vertices minus ``doc.origin``). Picking works on world coordinates, so rays get the origin
added back here, in float64.
"""

from __future__ import annotations

import numpy as np
import numpy.typing as npt
import viser

from selection import CameraModel, ScreenRect


def camera_model(client: viser.ClientHandle) -> CameraModel:
    """Return the client's current view as a pinhole ``CameraModel`` in the scene (local) frame.

    ``image_width``/``image_height`` are the canvas's drawing-buffer size; visible-only
    selection is judged at that resolution.
    """
    cam = client.camera
    height = max(int(cam.image_height), 1)
    width = max(int(cam.image_width), 1)
    return CameraModel(
        position=np.asarray(cam.position, dtype=np.float64),
        wxyz=np.asarray(cam.wxyz, dtype=np.float64),
        fov=float(cam.fov),
        aspect=float(cam.aspect),
        width=width,
        height=height,
    )


def world_ray(
    origin_local: npt.ArrayLike, direction: npt.ArrayLike, doc_origin: npt.NDArray[np.float64]
) -> tuple[npt.NDArray[np.float64], npt.NDArray[np.float64]]:
    """Return a viser ray (scene frame) as a world-frame origin and unit direction."""
    d = np.asarray(direction, dtype=np.float64)
    return np.asarray(origin_local, dtype=np.float64) + doc_origin, d / np.linalg.norm(d)


def screen_rect(event: viser.SceneRectSelectEvent) -> ScreenRect:
    """Return the rubber band of a rect-select event (normalised OpenCV coordinates)."""
    return ScreenRect.from_corners(event.screen_min, event.screen_max)
