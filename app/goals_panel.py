"""The goal tool and the "Goals" folder: place 6-D poses on the surface, list, edit, export.

Mouse-down on the map fixes the position, the drag sets the heading in the face plane, release
creates the goal (axes as the RViz MeshGoal tool sets them: see ``geometry.pose``). Every edit
of the list is one undoable document change.
"""

from __future__ import annotations

import logging
import math
import threading
from dataclasses import dataclass, replace
from typing import TYPE_CHECKING

import numpy as np
import numpy.typing as npt
import viser

from app.adapters import camera_model, world_ray
from app.notify import guarded, notify_error, notify_info
from app.refresher import Refresher
from geometry import vertex_normals
from geometry.pose import (
    drag_point_on_plane,
    interpolated_normal,
    matrix_from_quaternion,
    surface_pose,
    yaw_of,
)
from storage import (
    DocumentChanged,
    Goal,
    GoalsAtom,
    MapDocument,
    MeshmarkError,
    goals_from_json,
    goals_from_yaml,
    goals_to_json,
    goals_to_yaml,
)

if TYPE_CHECKING:
    from app.server import MeshmarkApp

logger = logging.getLogger(__name__)

GOALS_ROOT = "/goals"
PREVIEW_NODE = "/tools/goal_preview"
NO_GOALS = "(no goals)"


@dataclass
class _Drag:
    face: int
    point: npt.NDArray[np.float64]  # world
    normal: npt.NDArray[np.float64]  # flat face normal (or interpolated), not yet flipped


def _wxyz(xyzw: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    x, y, z, w = xyzw
    return (w, x, y, z)


class GoalsPanel:
    """Goal list controls, the goal tool's drag, and the goal markers in the scene."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self._drags: dict[int, _Drag] = {}
        self._drags_lock = threading.Lock()
        self._normals: tuple[MapDocument, np.ndarray] | None = None
        self._nodes: list[viser.SceneNodeHandle] = []
        self.start_name: str | None = None
        self.goal_name: str | None = None
        self.selected = gui.add_dropdown("Goal", options=[NO_GOALS])
        self.listing = gui.add_html("")
        self.new_name = gui.add_text("Rename to", initial_value="")
        self.rename = gui.add_button("Rename")
        order = gui.add_button_group("Order", options=("Up", "Down", "Delete"))
        role = gui.add_button_group("Plan", options=("Use as start", "Use as goal"))
        self.fly = gui.add_button("Fly to")
        self.interpolated = gui.add_checkbox(
            "Interpolated normal",
            initial_value=False,
            hint="z axis from the interpolated vertex normal instead of the flat face normal",
        )
        self.frame_id = gui.add_text("Frame id", initial_value="map")
        export = gui.add_button_group("Export", options=("YAML", "JSON"))
        self.upload = gui.add_upload_button("Import goals", hint="YAML or JSON (as exported)")

        self.rename.on_click(guarded("rename the goal")(lambda _e: self._rename()))
        order.on_click(guarded("edit the goals")(lambda e: self._order(e.target.value)))
        role.on_click(guarded("mark the goal")(lambda e: self._role(e.target.value)))
        self.fly.on_click(guarded("fly to the goal")(self._fly))
        export.on_click(guarded("export the goals")(self._export))
        self.upload.on_upload(guarded("import the goals")(self._import))
        self._refresher = Refresher(self.refresh, "goals-panel")

    # ------------------------------------------------------------------ document
    @property
    def doc(self) -> MapDocument:
        """Return the open map."""
        return self.app.doc

    def show(self, doc: MapDocument) -> None:
        """Show the goals of a newly opened map."""
        self.start_name = self.goal_name = None
        self._refresher.request()

    def document_changed(self, event: object) -> None:
        """Refresh when the goal list changed (called under the document lock: stay cheap)."""
        if isinstance(event, DocumentChanged) and isinstance(event.atom, GoalsAtom):
            # A role belongs to the goal it was given to: once that goal is gone (deleted,
            # undone, renamed by an undo) a later goal that gets its name must not inherit it.
            names = {g.name for g in event.atom.new}
            if self.start_name not in names:
                self.start_name = None
            if self.goal_name not in names:
                self.goal_name = None
            self._refresher.request()

    def refresh(self) -> None:
        """Redraw the goal markers and the list."""
        doc = self.doc
        goals = doc.goals
        scene = self.app.server.scene
        for handle in reversed(self._nodes):  # a name label before the frame it hangs on
            handle.remove()
        self._nodes = []
        diag = float(np.linalg.norm(np.ptp(doc.vertices_local, axis=0))) if doc.n_vertices else 1
        size = max(diag * 0.03, 0.05)
        for i, goal in enumerate(goals):
            position = tuple(float(x) for x in np.asarray(goal.position) - doc.origin)
            frame = scene.add_frame(
                f"{GOALS_ROOT}/{i}",
                wxyz=_wxyz(goal.orientation_xyzw),
                position=position,
                axes_length=size,
                axes_radius=size * 0.08,
            )
            label = scene.add_label(f"{GOALS_ROOT}/{i}/name", goal.name)
            self._nodes += [frame, label]
        names = [g.name for g in goals] or [NO_GOALS]
        current = self.selected.value
        self.selected.options = names
        self.selected.value = current if current in names else names[-1]
        self.listing.content = self._listing_html(goals)

    def _listing_html(self, goals: tuple[Goal, ...]) -> str:
        rows = []
        for g in goals:
            yaw = yaw_of(g.orientation_xyzw)
            yaw_text = "vertical" if math.isnan(yaw) else f"{math.degrees(yaw):.0f}°"
            role = " (start)" if g.name == self.start_name else ""
            role += " (goal)" if g.name == self.goal_name else ""
            x, y, z = g.position
            rows.append(
                f"<div><b>{_esc(g.name)}</b>{role}: ({x:.2f}, {y:.2f}, {z:.2f}), "
                f"yaw {yaw_text}</div>"
            )
        return "<div style='font-size:12px'>" + ("".join(rows) or "no goals yet") + "</div>"

    # ------------------------------------------------------------------ creating goals
    def _normal_at(self, face: int, point: npt.NDArray[np.float64]) -> npt.NDArray[np.float64]:
        doc = self.doc
        tri = doc.vertices[doc.faces[face]]
        flat = np.cross(tri[1] - tri[0], tri[2] - tri[0])
        if not self.interpolated.value:
            return flat
        cached = self._normals
        if cached is None or cached[0] is not doc:
            cached = (doc, vertex_normals(doc.vertices, doc.faces))
            self._normals = cached
        return interpolated_normal(doc.vertices, cached[1], doc.faces[face], point)

    def add_goal(
        self,
        face: int,
        point_world: npt.NDArray[np.float64],
        drag_world: npt.NDArray[np.float64] | None,
        client: viser.ClientHandle | None,
        normal: npt.NDArray[np.float64] | None = None,
    ) -> Goal:
        """Append a goal at ``point_world`` on ``face`` heading toward ``drag_world``."""
        doc = self.doc
        eye = self._eye(client)
        n = self._normal_at(face, point_world) if normal is None else normal
        try:
            position, xyzw = surface_pose(point_world, n, eye, drag_world)
        except ValueError as exc:  # a degenerate face
            raise MeshmarkError(f"cannot set a pose on face {face}: {exc}") from exc
        names = {g.name for g in doc.goals}
        k = len(doc.goals) + 1
        while f"goal{k}" in names:
            k += 1
        goal = Goal(
            f"goal{k}",
            tuple(float(x) for x in position),  # type: ignore[arg-type]
            tuple(float(x) for x in xyzw),  # type: ignore[arg-type]
            self.frame_id.value.strip() or "map",
        )
        doc.set_goals([*doc.goals, goal])
        return goal

    def _eye(self, client: viser.ClientHandle | None) -> npt.NDArray[np.float64]:
        if client is None:
            return self.doc.origin + np.array([0.0, 0.0, 1e6])
        return np.asarray(client.camera.position, dtype=np.float64) + self.doc.origin

    def drag(self, event: viser.SceneNodeDragEvent) -> None:
        """Goal tool drag: start fixes the position, update shows the heading, end creates."""
        doc = self.doc
        cid = event.client_id
        if event.phase == "start":
            index = self.app.index_or_notify(event.client)
            if index is None:
                return
            camera = camera_model(event.client)
            origins, directions = camera.rays(np.asarray([event.start_screen_pos], float))
            origin, direction = world_ray(origins[0], directions[0], doc.origin)
            hit = index.pick(origin, direction)
            face = int(hit.face_ids[0])
            if face < 0:
                return
            point = origin + direction * float(hit.distances[0])
            with self._drags_lock:
                self._drags[cid] = _Drag(face, point, self._normal_at(face, point))
            self._preview(event, point)
            return
        with self._drags_lock:
            state = self._drags.get(cid) if event.phase == "update" else self._drags.pop(cid, None)
        if state is None:
            return
        target = self._drag_target(event, state)
        if event.phase == "update":
            self._preview(event, state.point, target)
            return
        preview = self.app.server.scene.get_handle_by_name(PREVIEW_NODE)
        if preview is not None:
            preview.remove()
        goal = self.add_goal(state.face, state.point, target, event.client, normal=state.normal)
        notify_info(event.client, "Goal added", goal.name, seconds=3)

    def _drag_target(self, event: viser.SceneNodeDragEvent, state: _Drag) -> np.ndarray:
        """Return where the pointer meets the face plane (or viser's drag point, projected)."""
        doc = self.doc
        camera = camera_model(event.client)
        origins, directions = camera.rays(np.asarray([event.end_screen_pos], float))
        origin, direction = world_ray(origins[0], directions[0], doc.origin)
        hit = drag_point_on_plane(origin, direction, state.point, state.normal)
        if hit is not None:
            return hit
        return np.asarray(event.end_position, dtype=np.float64) + doc.origin

    def _preview(
        self,
        event: viser.SceneNodeDragEvent,
        point: npt.NDArray[np.float64],
        target: npt.NDArray[np.float64] | None = None,
    ) -> None:
        doc = self.doc
        with self._drags_lock:
            state = self._drags.get(event.client_id)
        normal = state.normal if state is not None else np.array([0.0, 0.0, 1.0])
        try:
            position, xyzw = surface_pose(point, normal, self._eye(event.client), target)
        except ValueError:
            return
        axes = matrix_from_quaternion(xyzw)
        length = float(np.linalg.norm(target - point)) if target is not None else 0.5
        length = max(length, 0.2)
        start = position - doc.origin
        segments = np.array([[start, start + axes[:, 0] * length]], dtype=np.float32)
        self.app.server.scene.add_line_segments(
            PREVIEW_NODE, segments, colors=(255, 120, 0), thickness=4.0, thickness_units="screen"
        )

    # ------------------------------------------------------------------ list editing
    def _index(self) -> int:
        names = [g.name for g in self.doc.goals]
        if self.selected.value not in names:
            raise MeshmarkError("there is no goal yet: choose the Goal tool and click the map")
        return names.index(self.selected.value)

    def _rename(self) -> None:
        i = self._index()
        name = self.new_name.value.strip()
        goals = list(self.doc.goals)
        if not name:
            raise MeshmarkError("type the new name first")
        if any(g.name == name for j, g in enumerate(goals) if j != i):
            raise MeshmarkError(f"a goal named {name!r} exists already")
        old = goals[i].name
        goals[i] = replace(goals[i], name=name)
        with self.doc.lock:  # the roles follow the name before the change is announced
            self.start_name = name if self.start_name == old else self.start_name
            self.goal_name = name if self.goal_name == old else self.goal_name
            self.doc.set_goals(goals)
        self.selected.value = name
        self.new_name.value = ""

    def _order(self, action: str) -> None:
        i = self._index()
        goals = list(self.doc.goals)
        if action == "Delete":
            goals.pop(i)
        else:
            j = i - 1 if action == "Up" else i + 1
            if not 0 <= j < len(goals):
                return
            goals[i], goals[j] = goals[j], goals[i]
        self.doc.set_goals(goals)

    def _role(self, action: str) -> None:
        with self.doc.lock:  # no goal change between reading the name and marking it
            name = self.doc.goals[self._index()].name
            if action == "Use as start":
                self.start_name = name
            else:
                self.goal_name = name
        self._refresher.request()

    def _fly(self, event: viser.GuiEvent) -> None:
        goal = self.doc.goals[self._index()]
        target = np.asarray(goal.position) - self.doc.origin
        z = matrix_from_quaternion(goal.orientation_xyzw)[:, 2]
        diag = float(np.linalg.norm(np.ptp(self.doc.vertices_local, axis=0)))
        distance = max(diag * 0.15, 1.0)
        eye = target + (z * 0.8 + np.array([0.0, -0.6, 0.0])) * distance
        clients = [event.client] if event.client is not None else []
        for client in clients:
            client.camera.position = tuple(eye)
            client.camera.look_at = tuple(target)
            client.camera.up_direction = (0.0, 0.0, 1.0)

    def _export(self, event: viser.GuiEvent) -> None:
        fmt = event.target.value
        goals = list(self.doc.goals)
        if not goals:
            raise MeshmarkError("there are no goals to export")
        origin = self.doc.origin if self.doc.origin.any() else None
        stem = self.doc.path.stem if self.doc.path else "map"
        if fmt == "YAML":
            data, name = goals_to_yaml(goals, origin=origin), f"{stem}_goals.yaml"
        else:
            data, name = goals_to_json(goals, origin=origin), f"{stem}_goals.json"
        if event.client is not None:
            event.client.send_file_download(name, data.encode(), save_immediately=True)

    def _import(self, event: viser.GuiEvent) -> None:
        upload = self.upload.value
        if len(upload.content) > 16 * 2**20:
            notify_error(event.client, "Import goals", f"{upload.name}: larger than 16 MiB")
            return
        parse = goals_from_json if upload.name.lower().endswith(".json") else goals_from_yaml
        goals = parse(upload.content, source=upload.name)
        with self.doc.lock:  # names are made unique against the list they are appended to
            current = self.doc.goals
            taken = {g.name for g in current}
            renamed = []
            for goal in goals:
                name, k = goal.name, 1
                while name in taken:  # "dock" -> "dock (imported)" -> "dock (imported 2)" ...
                    name = f"{goal.name} (imported)" if k == 1 else f"{goal.name} (imported {k})"
                    k += 1
                taken.add(name)
                renamed.append(goal if name == goal.name else replace(goal, name=name))
            self.doc.set_goals([*current, *renamed])
        notify_info(event.client, "Goals imported", f"{len(goals)} goals from {upload.name}")


def _esc(text: str) -> str:
    import html

    return html.escape(text)
