"""Tool modes (navigate, pick, brush, rubber band, erase, goal) and their pointer handling.

One scene-level click and one rect-select handler serve every client; drag callbacks are
attached to the base and label-overlay nodes only while a dragging tool is active, so a plain
left-drag orbits the camera in the other modes. Tools never touch the scene's map nodes: they
call document methods, and the view follows the document's events.
"""

from __future__ import annotations

import enum
import logging
import threading
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
import viser

from app.adapters import camera_model, screen_rect, world_ray
from app.notify import guarded, notify_error, notify_info
from selection import RectMode
from storage import UNLABELLED

if TYPE_CHECKING:
    from app.server import MeshmarkApp

logger = logging.getLogger(__name__)

BRUSH_NODE = "/tools/brush"


class ToolMode(enum.Enum):
    """What a click or a drag on the map does."""

    NAVIGATE = "Navigate"
    PICK = "Pick"
    BRUSH = "Brush"
    RECT = "Rubber band"
    ERASE = "Erase"
    GOAL = "Goal"


HOTKEYS = {
    ToolMode.NAVIGATE: "N",
    ToolMode.PICK: "P",
    ToolMode.BRUSH: "B",
    ToolMode.RECT: "R",
    ToolMode.ERASE: "E",
    ToolMode.GOAL: "G",
}
DRAG_MODES = (ToolMode.BRUSH, ToolMode.ERASE, ToolMode.GOAL)


class _Stroke:
    """One brush or erase drag: its last surface point, for filling gaps between events."""

    def __init__(self, instance_id: int) -> None:
        self.instance_id = instance_id
        self.last_point: npt.NDArray[np.float64] | None = None


class ToolPanel:
    """The "Tools" folder and the pointer callbacks that carry out the active tool."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self.mode = gui.add_dropdown(
            "Tool", options=[m.value for m in ToolMode], initial_value=ToolMode.NAVIGATE.value
        )
        self.status = gui.add_markdown("")
        self.toggle = gui.add_checkbox(
            "Click toggles",
            initial_value=True,
            hint="Pick: a click on a face with the active label removes it",
        )
        self.radius = gui.add_slider(
            "Brush radius", min=0.01, max=5.0, step=0.01, initial_value=0.3
        )
        self.connected = gui.add_checkbox(
            "Connected only",
            initial_value=True,
            hint="brush only faces reachable over the surface from the stroke (not through walls)",
        )
        self.rect_mode = gui.add_dropdown(
            "Rubber band",
            options=("visible only", "through"),
            initial_value="visible only",
            hint="Shift + drag: label what the camera sees, or everything in the rectangle",
        )
        gui.add_markdown(
            "<small>Shift + drag: rubber band · drag on the map: brush / erase / goal · "
            "keys N P B R E G switch tools · Ctrl+Z / Ctrl+Y undo / redo</small>"
        )
        for mode, key in HOTKEYS.items():
            command = gui.add_command(f"{mode.value} tool", hotkey=key)
            command.on_trigger(lambda _e, m=mode: self.set_mode(m))
        self.mode.on_update(guarded("switch tools")(lambda _e: self._mode_changed()))
        self._strokes: dict[int, _Stroke] = {}
        self._strokes_lock = threading.Lock()
        self._drag_nodes: list[viser.SceneNodeHandle] = []
        self._drag_lock = threading.Lock()
        server = app.server
        server.scene.on_click()(guarded("use the tool")(self._on_click))
        server.scene.on_rect_select(modifier="shift")(guarded("select")(self._on_rect))

    # ------------------------------------------------------------------ modes
    @property
    def tool(self) -> ToolMode:
        """Return the active tool."""
        return ToolMode(self.mode.value)

    def set_mode(self, mode: ToolMode) -> None:
        """Switch tools (also what the hotkeys do)."""
        self.mode.value = mode.value

    def _mode_changed(self) -> None:
        self.refresh_drag_bindings()
        brush = self.app.server.scene.get_handle_by_name(BRUSH_NODE)
        if brush is not None and self.tool not in (ToolMode.BRUSH, ToolMode.ERASE):
            brush.visible = False

    def refresh_drag_bindings(self) -> None:
        """Attach drag callbacks to every map node while a dragging tool is active."""
        with self._drag_lock:
            for handle in self._drag_nodes:
                try:
                    handle.remove_drag_callback("all")
                except Exception:  # the node may have been removed meanwhile
                    logger.debug("could not detach drag callback", exc_info=True)
            self._drag_nodes = []
            if self.tool in DRAG_MODES:
                for handle in self.app.map_nodes():
                    self._bind(handle)

    def bind_new_node(self, handle: viser.SceneNodeHandle) -> None:
        """Give a newly created map node (an overlay chunk) the active drag binding."""
        if self.tool in DRAG_MODES:
            with self._drag_lock:
                self._bind(handle)

    def _bind(self, handle: viser.SceneNodeHandle) -> None:
        handle.on_drag("left")(self._on_drag)
        self._drag_nodes.append(handle)

    def set_status(self, text: str) -> None:
        """Show a one-line status under the tool selector (e.g. "indexing…")."""
        self.status.content = text

    # ------------------------------------------------------------------ labelling
    def _target_label(self, client: viser.ClientHandle | None) -> int | None:
        """Return the instance id to paint with (-1 for erase), or None after telling why."""
        if self.tool is ToolMode.ERASE:
            return UNLABELLED
        iid = self.app.label_panel.active_instance()
        if iid is None:
            notify_error(
                client,
                "No active label",
                "Add a class in the Labels panel first (type a name, press 'Add class').",
            )
        return iid

    def _on_click(self, event: viser.SceneClickEvent) -> None:
        tool = self.tool
        if tool is ToolMode.NAVIGATE:
            return
        index = self.app.index_or_notify(event.client)
        if index is None:
            return
        doc = self.app.doc
        origin, direction = world_ray(event.ray_origin, event.ray_direction, doc.origin)
        hit = index.pick(origin, direction)
        face = int(hit.face_ids[0])
        if face < 0:
            return
        if tool is ToolMode.GOAL:
            point = origin + direction * float(hit.distances[0])
            self.app.add_goal(face, point, None, event.client)
            return
        iid = self._target_label(event.client)
        if iid is None:
            return
        if tool in (ToolMode.BRUSH, ToolMode.ERASE):  # a click is one brush dab
            point = origin + direction * float(hit.distances[0])
            with doc.gesture():
                doc.label_faces(self.app.brush_faces(point, face, self.brush_settings()), iid)
            return
        if tool is ToolMode.PICK and self.toggle.value and doc.face_labels[face] == iid:
            iid = UNLABELLED
        doc.label_faces([face], iid)

    def _on_rect(self, event: viser.SceneRectSelectEvent) -> None:
        if self.tool in (ToolMode.NAVIGATE, ToolMode.GOAL):
            notify_info(
                event.client, "Rubber band", "Choose Pick, Brush, Rubber band or Erase first."
            )
            return
        selector = self.app.rect_selector_or_notify(event.client)
        if selector is None:
            return
        iid = self._target_label(event.client)
        if iid is None:
            return
        mode = RectMode.VISIBLE if self.rect_mode.value == "visible only" else RectMode.THROUGH
        faces = selector.select(camera_model(event.client), screen_rect(event), mode=mode)
        with self.app.doc.gesture():
            self.app.doc.label_faces(faces, iid)
        notify_info(event.client, "Rubber band", f"{len(faces):,} faces ({mode.value})", seconds=3)

    def brush_settings(self) -> tuple[float, bool]:
        """Return (radius in metres, connected only)."""
        return float(self.radius.value), bool(self.connected.value)

    async def _on_drag(self, event: viser.SceneNodeDragEvent) -> None:
        # async: viser runs it on its event loop in message order (phases never interleave).
        try:
            if self.tool is ToolMode.GOAL:
                self.app.goal_drag(event)
            else:
                self._brush_drag(event)
        except Exception as exc:  # report, and never leave a gesture open
            from app.notify import report_exception

            self.app.finish_gestures()
            report_exception(event.client, exc, "paint")

    def _brush_drag(self, event: viser.SceneNodeDragEvent) -> None:
        doc = self.app.doc
        client_id = event.client_id
        if event.phase == "start":
            iid = self._target_label(event.client)
            if iid is None:
                return
            index = self.app.index_or_notify(event.client)
            if index is None:
                return
            with self._strokes_lock:
                self._strokes[client_id] = _Stroke(iid)
            doc.begin_gesture()
            self._paint_at(event, event.start_screen_pos)
        elif event.phase == "update":
            self._paint_at(event, event.end_screen_pos)
        else:
            self._paint_at(event, event.end_screen_pos)
            with self._strokes_lock:
                stroke = self._strokes.pop(client_id, None)
            if stroke is not None:
                doc.commit_gesture()
            brush = self.app.server.scene.get_handle_by_name(BRUSH_NODE)
            if brush is not None:
                brush.visible = False

    def _paint_at(self, event: viser.SceneNodeDragEvent, screen_xy: tuple[float, float]) -> None:
        """Paint a brush dab under the pointer, and along the straight gap since the last one."""
        with self._strokes_lock:
            stroke = self._strokes.get(event.client_id)
        index = self.app.index
        if stroke is None or index is None:
            return
        doc = self.app.doc
        camera = camera_model(event.client)
        eye = camera.position + doc.origin
        origins, directions = camera.rays(np.asarray([screen_xy], dtype=np.float64))
        origin, direction = world_ray(origins[0], directions[0], doc.origin)
        hit = index.pick(origin, direction)
        if hit.face_ids[0] < 0:
            return
        point = origin + direction * float(hit.distances[0])
        radius, connected = self.brush_settings()
        targets = point[None, :]
        if stroke.last_point is not None:
            gap = float(np.linalg.norm(point - stroke.last_point))
            steps = int(np.ceil(gap / (0.5 * radius)))
            if steps > 1:  # drag events arrive at <= 20 Hz: fill the path between them
                ts = np.linspace(0.0, 1.0, steps + 1)[1:, None]
                targets = stroke.last_point + ts * (point - stroke.last_point)
        stroke.last_point = point
        # Each straight-line sample goes back onto the surface along the view ray.
        rays = targets - eye
        rays /= np.linalg.norm(rays, axis=1, keepdims=True)
        hits = index.pick(np.repeat(eye[None, :], len(rays), axis=0), rays)
        ok = hits.face_ids >= 0
        if ok.any():
            centres = eye + rays[ok] * hits.distances[ok, None]
            faces = self.app.brush_faces(centres, hits.face_ids[ok], (radius, connected))
            doc.label_faces(faces, stroke.instance_id)
        self.app.show_brush(point - doc.origin, radius)
