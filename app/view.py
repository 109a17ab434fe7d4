"""The scene: the map's base mesh in the chosen display mode, and its wireframe.

Only this module creates scene nodes for the map. Everything is drawn in the document's
local frame (``vertices_local``), so big UTM coordinates keep float32 precision.
"""

from __future__ import annotations

import enum
import logging
import threading
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np
import viser

from app.colormaps import colorize
from app.glb import colored_glb, textured_glb
from storage import MapDocument

logger = logging.getLogger(__name__)

BASE_NODE = "/map/base"
WIRE_NODE = "/map/wireframe"


class DisplayMode(enum.Enum):
    """How the base mesh is coloured (the Mesh Tools display modes)."""

    FIXED = "Fixed colour"
    VERTEX_COLORS = "Vertex colours"
    COST_LAYER = "Cost layer"
    TEXTURE = "Texture"


@dataclass(frozen=True)
class DisplaySettings:
    """Everything that decides what the base mesh looks like."""

    mode: DisplayMode = DisplayMode.FIXED
    color: tuple[int, int, int] = (170, 170, 170)
    layer: str | None = None
    cmap: str = "viridis"
    vmin: float = 0.0
    vmax: float = 1.0
    wireframe: bool = False
    opacity: float = 1.0

    def with_(self, **changes: object) -> DisplaySettings:
        """Return a copy with ``changes`` applied."""
        return replace(self, **changes)  # type: ignore[arg-type]


def available_modes(doc: MapDocument) -> list[DisplayMode]:
    """Return the display modes this map supports, in menu order."""
    modes = [DisplayMode.FIXED]
    if doc.vertex_colors is not None:
        modes.append(DisplayMode.VERTEX_COLORS)
    if doc.layers:
        modes.append(DisplayMode.COST_LAYER)
    if doc.texture is not None:
        modes.append(DisplayMode.TEXTURE)
    return modes


def default_mode(doc: MapDocument) -> DisplayMode:
    """Pick what a user most likely wants to see first: texture, then colours, then fixed."""
    modes = available_modes(doc)
    for mode in (DisplayMode.TEXTURE, DisplayMode.VERTEX_COLORS):
        if mode in modes:
            return mode
    return DisplayMode.FIXED


class MapView:
    """Draws one document's base mesh and wireframe; re-sends only what a change needs."""

    def __init__(
        self, server: viser.ViserServer, *, on_base: Callable[[], None] | None = None
    ) -> None:
        self.server = server
        self._on_base = on_base
        self._lock = threading.Lock()
        self._doc: MapDocument | None = None
        self._shown: DisplaySettings | None = None
        self._base: viser.SceneNodeHandle | None = None
        self._wire: viser.MeshHandle | None = None
        self.sent_bytes = 0  #: size of the last base payload, for progress decisions and tests

    def show(self, doc: MapDocument, settings: DisplaySettings) -> None:
        """Draw ``doc`` from scratch with ``settings`` (after opening a map)."""
        with self._lock:
            self._doc = doc
            self._shown = None
            self._remove(BASE_NODE)
            self._remove(WIRE_NODE)
            self._base = self._wire = None
        self.update(settings)

    def update(self, settings: DisplaySettings) -> None:
        """Bring the scene to ``settings``, touching only the nodes whose look changed."""
        with self._lock:
            doc = self._doc
            if doc is None:
                return
            old = self._shown
            if old is None or _base_changed(old, settings):
                before = self._base
                self._draw_base(doc, settings, old)
                if self._base is not before and self._on_base is not None:
                    self._on_base()  # a new node: pointer bindings must follow
            if old is None or old.wireframe != settings.wireframe:
                self._draw_wireframe(doc, settings.wireframe)
            self._shown = settings

    @property
    def base_handle(self) -> viser.SceneNodeHandle | None:
        """Return the base mesh node (it changes when the display mode needs a new node)."""
        return self._base

    @property
    def settings(self) -> DisplaySettings | None:
        """Return what is on screen now."""
        return self._shown

    def _draw_base(self, doc: MapDocument, s: DisplaySettings, old: DisplaySettings | None) -> None:
        opacity = None if s.opacity >= 1.0 else float(s.opacity)
        if s.mode is DisplayMode.FIXED:
            handle = self._base
            if (
                isinstance(handle, viser.MeshHandle)
                and old is not None
                and old.mode is DisplayMode.FIXED
            ):
                handle.color = s.color  # setters send only what differs
                handle.opacity = opacity
                return
            self._base = self.server.scene.add_mesh_simple(
                BASE_NODE,
                doc.vertices_local,
                doc.faces,
                color=s.color,
                opacity=opacity,
                side="double",
                cast_shadow=False,
                receive_shadow=False,
            )
            self.sent_bytes = doc.vertices_local.nbytes + doc.faces.nbytes
            return
        glb = self._glb(doc, s)
        self.sent_bytes = len(glb)
        self._base = self.server.scene.add_glb(
            BASE_NODE, glb, cast_shadow=False, receive_shadow=False
        )

    def _glb(self, doc: MapDocument, s: DisplaySettings) -> bytes:
        v, f = doc.vertices_local, doc.faces
        if s.mode is DisplayMode.TEXTURE and doc.texture is not None:
            t = doc.texture
            return textured_glb(v, f, t.uv, t.image, opacity=s.opacity)
        if s.mode is DisplayMode.VERTEX_COLORS and doc.vertex_colors is not None:
            colors = doc.vertex_colors
        elif s.mode is DisplayMode.COST_LAYER and s.layer in doc.layers:
            colors = colorize(doc.layers[s.layer], s.vmin, s.vmax, s.cmap)
        else:
            colors = np.broadcast_to(np.asarray(s.color, np.uint8), (len(v), 3))
        return colored_glb(v, f, np.ascontiguousarray(colors), opacity=s.opacity)

    def _draw_wireframe(self, doc: MapDocument, on: bool) -> None:
        if not on:
            self._remove(WIRE_NODE)
            self._wire = None
            return
        self._wire = self.server.scene.add_mesh_simple(
            WIRE_NODE,
            doc.vertices_local,
            doc.faces,
            color=(30, 30, 30),
            wireframe=True,
            cast_shadow=False,
            receive_shadow=False,
        )

    def _remove(self, name: str) -> None:
        handle = self.server.scene.get_handle_by_name(name)
        if handle is not None:
            handle.remove()

    def redraw_layer(self, name: str) -> None:
        """Re-send the base when the layer on screen changed its values."""
        with self._lock:
            s = self._shown
            doc = self._doc
            if doc is None or s is None or s.mode is not DisplayMode.COST_LAYER or s.layer != name:
                return
            self._draw_base(doc, s, None)
        if self._on_base is not None:
            self._on_base()


def _base_changed(old: DisplaySettings, new: DisplaySettings) -> bool:
    if old.mode != new.mode or old.opacity != new.opacity:
        return True
    if new.mode is DisplayMode.FIXED:
        return old.color != new.color
    if new.mode is DisplayMode.COST_LAYER:
        return (old.layer, old.cmap, old.vmin, old.vmax) != (
            new.layer,
            new.cmap,
            new.vmin,
            new.vmax,
        )
    return False
