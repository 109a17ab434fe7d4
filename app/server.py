"""``MeshmarkApp``: one viser server showing one open map, with its panels, view and jobs."""

from __future__ import annotations

import logging
import tempfile
import threading
from collections.abc import Callable
from pathlib import Path

import numpy as np
import viser

from app.display_panel import DisplayPanel
from app.file_panel import FilePanel, describe
from app.goals_panel import GoalsPanel
from app.jobs import Jobs
from app.label_overlay import LabelOverlay
from app.label_panel import LabelPanel, face_areas
from app.layers_panel import LayersPanel
from app.notify import notify_info
from app.picking import Picking, PickingSlot, build_picking
from app.tools import BRUSH_NODE, ToolPanel
from app.view import DisplaySettings, MapView
from selection import MeshIndex, RectSelector
from storage import DocumentChanged, LayerAtom, MapDocument, load_map, save_map

logger = logging.getLogger(__name__)

DocumentListener = Callable[[MapDocument], None]


class MeshmarkApp:
    """The browser app around a ``MapDocument``: opening another map swaps the document."""

    def __init__(
        self,
        server: viser.ViserServer,
        doc: MapDocument,
        *,
        data_dir: Path | str = ".",
        max_upload_mb: float = 512.0,
    ) -> None:
        self.server = server
        self.data_dir = Path(data_dir).resolve()
        self.max_upload_bytes = int(max_upload_mb * 2**20)
        self.jobs = Jobs()
        self._swap_lock = threading.RLock()
        self._unsubscribe: Callable[[], None] | None = None
        self._shown_dirty = False
        self.doc = doc
        self.document_listeners: list[DocumentListener] = []
        server.scene.set_up_direction("+z")
        server.scene.configure_default_lights(cast_shadow=False)
        self._picking = PickingSlot()
        self._areas: tuple[MapDocument, np.ndarray] | None = None
        self.view = MapView(server, on_base=self._base_replaced)
        gui = server.gui
        gui.configure_theme(control_width="medium")
        with gui.add_folder("Map"):
            self.file_panel = FilePanel(self, gui)
        with gui.add_folder("Display"):
            self.display_panel = DisplayPanel(self, gui)
        with gui.add_folder("Tools"):
            self.tool_panel = ToolPanel(self, gui)
        with gui.add_folder("Labels"):
            self.label_panel = LabelPanel(self, gui)
        with gui.add_folder("Cost layers", expand_by_default=False):
            self.layers_panel = LayersPanel(self, gui)
        with gui.add_folder("Goals", expand_by_default=False):
            self.goals_panel = GoalsPanel(self, gui)
        self.overlay = LabelOverlay(server, on_node=self.tool_panel.bind_new_node)
        self.install(doc)

    # ------------------------------------------------------------------ documents
    def install(self, doc: MapDocument) -> None:
        """Make ``doc`` the open map: draw it, frame it, refresh every panel."""
        with self._swap_lock:
            if self._unsubscribe is not None:
                self._unsubscribe()
            self.doc = doc
            self._picking.set(None)
            self._unsubscribe = doc.subscribe(self._on_document_event)
            settings = self.display_panel.reset_for(doc)
            self.view.show(doc, settings)
            self.overlay.show(doc)
            self._frame_camera(doc)
            self._shown_dirty = doc.dirty
            self.file_panel.refresh(doc)
            self.label_panel.refresh()
            self.layers_panel.show(doc)
            self.goals_panel.show(doc)
            for listener in list(self.document_listeners):
                listener(doc)
        self.tool_panel.set_status("*indexing the map for picking…*")
        self.jobs.submit(f"Indexing {doc.n_faces:,} faces", lambda: self._index(doc))

    def _index(self, doc: MapDocument) -> None:
        picking = build_picking(doc)
        if doc is self.doc:
            self._picking.set(picking)
            self.tool_panel.set_status("")
            logger.info("picking ready in %.2f s (%d faces)", picking.build_s, doc.n_faces)

    def _on_document_event(self, event: object) -> None:
        # Called under the document lock: keep it cheap, hand real work to the job thread.
        if isinstance(event, DocumentChanged) and isinstance(event.atom, LayerAtom):
            name = event.atom.name
            self.jobs.submit("Updating layers", lambda: self._layers_changed(name))
        self.label_panel.document_changed()
        self.layers_panel.document_changed(event)
        self.goals_panel.document_changed(event)
        if self.doc.dirty != self._shown_dirty:  # the summary's unsaved marker
            self._shown_dirty = self.doc.dirty
            self.file_panel.info.content = describe(self.doc)

    def _layers_changed(self, name: str) -> None:
        self.display_panel.refresh_layers(self.doc)
        self.view.redraw_layer(name)

    def open_path(
        self, path: Path, client: viser.ClientHandle | None, *, uploaded: bool = False
    ) -> None:
        """Load ``path`` in the background; on success it replaces the open map."""

        def load() -> MapDocument:
            doc = load_map(path)
            if uploaded:
                doc.path = None
                doc.meta_update(source_name=path.name, uploaded=True)
            return doc

        def done(doc: MapDocument) -> None:
            self.install(doc)
            for warning in doc.warnings[:3]:
                notify_info(client, f"{path.name}: repaired while reading", warning, seconds=10)

        self.jobs.submit(
            f"Loading {path.name}",
            load,
            client=client,
            on_done=done,
            done_message=lambda d: f"{d.n_vertices:,} vertices, {d.n_faces:,} faces",
        )

    def confirm_discard(
        self, client: viser.ClientHandle | None, action: Callable[[], None]
    ) -> None:
        """Run ``action`` now, or after the person agrees to drop unsaved edits."""
        if not self.doc.dirty or client is None:
            action()
            return
        with client.gui.add_modal("Unsaved changes") as modal:
            client.gui.add_markdown(
                "The open map has edits that are not saved. Open another map and drop them?"
            )
            discard = client.gui.add_button("Discard changes and open", color="red")
            cancel = client.gui.add_button("Cancel")

            @discard.on_click
            def _(_: viser.GuiEvent) -> None:
                modal.close()
                action()

            @cancel.on_click
            def _(_: viser.GuiEvent) -> None:
                modal.close()

    def save(self, path: Path, client: viser.ClientHandle | None) -> None:
        """Write the open map to ``path`` (atomically) in the background."""
        doc = self.doc

        def write() -> Path:
            save_map(doc, path)
            doc.mark_saved(path)
            doc.meta_update(uploaded=False)
            return path

        self.jobs.submit(
            f"Saving {path.name}",
            write,
            client=client,
            on_done=lambda _: self._after_save(doc),
            done_message=lambda p: f"written to {p}",
        )

    def _after_save(self, doc: MapDocument) -> None:
        self._shown_dirty = doc.dirty
        self.file_panel.refresh(doc)

    def download(self, client: viser.ClientHandle) -> None:
        """Send the open map as an HDF5 file to the browser."""
        doc = self.doc
        stem = Path(doc.path.name if doc.path else doc.meta.get("source_name", "map")).stem

        def build() -> bytes:
            with tempfile.TemporaryDirectory(prefix="meshmark-dl-") as tmp:
                target = Path(tmp) / f"{stem}.h5"
                save_map(doc, target)
                return target.read_bytes()

        def send(data: bytes) -> None:
            client.send_file_download(f"{stem}.h5", data, save_immediately=True)

        self.jobs.submit(f"Preparing {stem}.h5", build, client=client, on_done=send)

    def redraw(self, settings: DisplaySettings, *, client: viser.ClientHandle | None) -> None:
        """Bring the scene to ``settings``; big maps do it as a job with progress."""
        if self.doc.n_faces > 200_000:
            self.jobs.submit("Redrawing the map", lambda: self.view.update(settings), client=client)
        else:
            self.view.update(settings)

    def _frame_camera(self, doc: MapDocument) -> None:
        v = doc.vertices_local
        if len(v) == 0:
            return
        lo, hi = v.min(axis=0).astype(float), v.max(axis=0).astype(float)
        centre = (lo + hi) / 2
        diag = float(np.linalg.norm(hi - lo)) or 1.0
        position = centre + np.array([0.0, -0.6, 0.55]) * diag  # fits at the default 75° fov
        cam = self.server.initial_camera
        cam.position = tuple(position)
        cam.look_at = tuple(centre)
        cam.up = (0.0, 0.0, 1.0)
        for client in self.server.get_clients().values():
            client.camera.position = tuple(position)
            client.camera.look_at = tuple(centre)
            client.camera.up_direction = (0.0, 0.0, 1.0)

    # ------------------------------------------------------------------ picking and tools
    @property
    def picking(self) -> Picking | None:
        """Return the selection structures of the open map, or None while indexing."""
        return self._picking.get(self.doc)

    @property
    def index(self) -> MeshIndex | None:
        """Return the Embree index of the open map, or None while it is being built."""
        picking = self.picking
        return picking.index if picking is not None else None

    def index_or_notify(self, client: viser.ClientHandle | None) -> MeshIndex | None:
        """Return the index, or tell the person that indexing is still running."""
        index = self.index
        if index is None:
            notify_info(client, "Indexing…", "The map is still being indexed; try again shortly.")
        return index

    def rect_selector_or_notify(self, client: viser.ClientHandle | None) -> RectSelector | None:
        """Return the rubber-band selector, or tell the person that indexing is running."""
        picking = self.picking
        if picking is None:
            notify_info(client, "Indexing…", "The map is still being indexed; try again shortly.")
            return None
        return picking.rect

    def brush_faces(
        self, points_world: np.ndarray, seed_faces: np.ndarray, settings: tuple[float, bool]
    ) -> np.ndarray:
        """Return the faces brush dabs at ``points_world`` cover (empty while indexing)."""
        picking = self.picking
        if picking is None:
            return np.zeros(0, np.int32)
        radius, connected = settings
        return picking.brush(points_world, seed_faces, radius, connected)

    def show_brush(self, point_local: np.ndarray, radius: float) -> None:
        """Show the brush as a translucent ball at the stroke's current point."""
        handle = self.server.scene.get_handle_by_name(BRUSH_NODE)
        if handle is None or getattr(handle, "_meshmark_radius", None) != radius:
            handle = self.server.scene.add_icosphere(
                BRUSH_NODE,
                radius=radius,
                color=(255, 200, 0),
                opacity=0.35,
                subdivisions=2,
                cast_shadow=False,
                receive_shadow=False,
            )
            handle._meshmark_radius = radius  # type: ignore[attr-defined]
        handle.position = tuple(float(x) for x in point_local)
        handle.visible = True

    def map_nodes(self) -> list[viser.SceneNodeHandle]:
        """Return the nodes a pointer gesture may start on: the base mesh and label overlays."""
        base = self.view.base_handle
        return ([base] if base is not None else []) + self.overlay.handles()

    def _base_replaced(self) -> None:
        self.tool_panel.refresh_drag_bindings()

    def finish_gestures(self) -> None:
        """Close a gesture left open (a drag whose end never came) before undo/redo."""
        with self.doc.lock:
            if self.doc.history.is_open:
                self.doc.commit_gesture()

    def face_areas(self) -> np.ndarray:
        """Return (cached) face areas of the open map."""
        cached = self._areas
        if cached is None or cached[0] is not self.doc:
            cached = (self.doc, face_areas(self.doc.vertices_local, self.doc.faces))
            self._areas = cached
        return cached[1]

    # ------------------------------------------------------------------ goals
    def add_goal(self, *args: object, **kwargs: object) -> None:
        """Create a goal pose on the surface (see ``GoalsPanel.add_goal``)."""
        self.goals_panel.add_goal(*args, **kwargs)  # type: ignore[arg-type]

    def goal_drag(self, event: viser.SceneNodeDragEvent) -> None:
        """Carry out the goal tool's drag (see ``GoalsPanel.drag``)."""
        self.goals_panel.drag(event)

    def close(self) -> None:
        """Stop background work (the server is stopped by its owner)."""
        self.overlay.close()
        self.layers_panel.close()
        self.jobs.shutdown()
