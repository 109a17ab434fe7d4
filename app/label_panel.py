"""The "Labels" folder: classes and instances, the active label, counts, coverage, undo/redo.

Names are checked while the person types (mesh_tools writes ``<class>_<instance>``, so neither
part may contain ``_`` or ``/``) and the reason for a refusal is shown under the field.
"""

from __future__ import annotations

import colorsys
import html
import threading
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import viser

from app.notify import guarded
from app.refresher import Refresher
from storage import MapDocument, label_files_bytes, name_problem, ply_with_face_colors

if TYPE_CHECKING:
    from app.server import MeshmarkApp

NO_LABEL = "(no label yet)"
EXPORT_IDS = "Class ids (.npy + JSON)"
EXPORT_PLY = "PLY with face colours"


def label_key(class_name: str, instance: str) -> str:
    """Return how a label reads in the dropdown."""
    return f"{class_name} / {instance}"


def next_color(index: int) -> tuple[int, int, int]:
    """Return well separated, saturated colours (golden-angle hues) for new classes."""
    h = (index * 0.618033988749895 + 0.05) % 1.0
    r, g, b = colorsys.hsv_to_rgb(h, 0.8, 0.95)
    return (round(r * 255), round(g * 255), round(b * 255))


class LabelPanel:
    """Everything about label classes: create, rename, recolour, delete, pick the active one."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self._refresh_lock = threading.Lock()
        self.active = gui.add_dropdown("Active label", options=[NO_LABEL])
        self.name = gui.add_text("Name", initial_value="", hint="class or instance name")
        self.name_note = gui.add_markdown("")
        self.color = gui.add_rgb("Class colour", initial_value=next_color(0))
        with gui.add_folder("Create / edit", expand_by_default=True):
            self.add_class = gui.add_button("Add class", hint="new class with instance 1")
            self.add_instance = gui.add_button("Add instance", hint="new instance of the class")
            self.rename_class = gui.add_button("Rename class")
            self.rename_instance = gui.add_button("Rename instance")
            self.recolor = gui.add_button("Recolour class")
            self.delete_instance = gui.add_button("Delete instance", color="red")
            self.delete_class = gui.add_button("Delete class", color="red")
        self.coverage_bar = gui.add_progress_bar(0.0, color="green")
        self.summary = gui.add_html("")
        buttons = gui.add_button_group("History", options=("Undo", "Redo"))
        undo = gui.add_command("Undo", hotkey="z", modifier="cmd/ctrl")
        redo = gui.add_command("Redo", hotkey="y", modifier="cmd/ctrl")
        export = gui.add_button_group("Export", options=(EXPORT_IDS, EXPORT_PLY))

        self.name.on_update(guarded("check the name")(lambda _e: self._check_name()))
        self.add_class.on_click(guarded("add the class")(self._add_class))
        self.add_instance.on_click(guarded("add the instance")(self._add_instance))
        self.rename_class.on_click(guarded("rename the class")(self._rename_class))
        self.rename_instance.on_click(guarded("rename the instance")(self._rename_instance))
        self.recolor.on_click(guarded("recolour the class")(self._recolor))
        self.delete_instance.on_click(guarded("delete the instance")(self._delete_instance))
        self.delete_class.on_click(guarded("delete the class")(self._delete_class))
        self.active.on_update(guarded("choose the label")(lambda _e: self._active_changed()))
        buttons.on_click(guarded("undo")(lambda e: self._history(e.target.value)))
        undo.on_trigger(guarded("undo")(lambda _e: self._history("Undo")))
        redo.on_trigger(guarded("redo")(lambda _e: self._history("Redo")))
        export.on_click(guarded("export the labels")(self._export))
        self._check_name()
        self._refresher = Refresher(self.refresh, "label-panel")

    # ------------------------------------------------------------------ state
    @property
    def doc(self) -> MapDocument:
        """Return the open map."""
        return self.app.doc

    def active_instance(self) -> int | None:
        """Return the instance id the tools label with, or None when there is no label."""
        value = self.active.value
        for iid, inst in self.doc.instances.items():
            if label_key(inst.class_name, inst.name) == value:
                return iid
        return None

    def document_changed(self, _event: object = None) -> None:
        """Mark the panel for a refresh (cheap: called under the document lock)."""
        self._refresher.request()

    def refresh(self) -> None:
        """Show the current classes, instances, counts and coverage."""
        with self._refresh_lock:
            doc = self.doc
            with doc.lock:
                instances = dict(doc.instances)
                classes = dict(doc.classes)
                counts = doc.instance_face_counts()
                labelled = doc.face_labels >= 0
            options = [label_key(i.class_name, i.name) for i in instances.values()] or [NO_LABEL]
            current = self.active.value
            self.active.options = options
            if current in options:
                self.active.value = current
            n = max(doc.n_faces, 1)
            area = self.app.face_areas()
            total_area = float(area.sum()) or 1.0
            face_pct = 100.0 * labelled.sum() / n
            area_pct = 100.0 * float(area[labelled].sum()) / total_area
            self.coverage_bar.value = float(face_pct)
            self.summary.content = _summary_html(classes, instances, counts, face_pct, area_pct)

    # ------------------------------------------------------------------ callbacks
    def _check_name(self) -> bool:
        problem = name_problem(self.name.value, "name") if self.name.value else None
        self.name_note.content = (
            f"<span style='color:#c00'>{html.escape(problem)}</span>" if problem else ""
        )
        ok = problem is None and bool(self.name.value)
        for button in (self.add_class, self.add_instance, self.rename_class, self.rename_instance):
            button.disabled = not ok
        return ok

    def _active_class(self) -> str:
        iid = self.active_instance()
        if iid is None:
            raise _no_label()
        return self.doc.instances[iid].class_name

    def _add_class(self, _event: viser.GuiEvent) -> None:
        name = self.name.value.strip()
        with self.doc.gesture():
            self.doc.add_class(name, tuple(self.color.value))  # type: ignore[arg-type]
            self.doc.add_instance(name, "1")
        self.active.options = [*self.active.options, label_key(name, "1")]
        self.active.value = label_key(name, "1")
        self.name.value = ""
        self.color.value = next_color(len(self.doc.classes))

    def _add_instance(self, _event: viser.GuiEvent) -> None:
        cls = self._active_class()
        name = self.name.value.strip()
        self.doc.add_instance(cls, name)
        self.active.options = [*self.active.options, label_key(cls, name)]
        self.active.value = label_key(cls, name)
        self.name.value = ""

    def _rename_class(self, _event: viser.GuiEvent) -> None:
        iid = self.active_instance()
        cls = self._active_class()
        self.doc.rename_class(cls, self.name.value.strip())
        self._select(iid)
        self.name.value = ""

    def _rename_instance(self, _event: viser.GuiEvent) -> None:
        iid = self.active_instance()
        if iid is None:
            raise _no_label()
        self.doc.rename_instance(iid, self.name.value.strip())
        self._select(iid)
        self.name.value = ""

    def _recolor(self, _event: viser.GuiEvent) -> None:
        self.doc.recolor_class(self._active_class(), tuple(self.color.value))  # type: ignore[arg-type]

    def _delete_instance(self, _event: viser.GuiEvent) -> None:
        iid = self.active_instance()
        if iid is None:
            raise _no_label()
        self.doc.delete_instance(iid)

    def _delete_class(self, _event: viser.GuiEvent) -> None:
        self.doc.delete_class(self._active_class())

    def _active_changed(self) -> None:
        iid = self.active_instance()
        if iid is not None:
            cls = self.doc.classes.get(self.doc.instances[iid].class_name)
            if cls is not None:
                self.color.value = cls.color

    def _history(self, which: str) -> None:
        self.app.finish_gestures()
        if which == "Undo":
            self.doc.undo()
        else:
            self.doc.redo()

    def _export(self, event: viser.GuiEvent) -> None:
        if event.client is None:
            return
        doc = self.doc
        stem = Path(doc.path.name if doc.path else doc.meta.get("source_name", "map")).stem
        data = doc.snapshot()
        if event.target.value == EXPORT_PLY:
            ply = ply_with_face_colors(data)
            event.client.send_file_download(f"{stem}_labels.ply", ply, save_immediately=True)
        else:
            npy, text = label_files_bytes(data)
            event.client.send_file_download(f"{stem}_labels.npy", npy, save_immediately=True)
            event.client.send_file_download(
                f"{stem}_labels.json", text.encode("utf-8"), save_immediately=True
            )

    def _select(self, iid: int | None) -> None:
        self.refresh()
        if iid is not None and iid in self.doc.instances:
            inst = self.doc.instances[iid]
            self.active.value = label_key(inst.class_name, inst.name)


def _no_label() -> Exception:
    from storage import DocumentError

    return DocumentError("add a class first (type a name, then press 'Add class')")


def _summary_html(classes, instances, counts, face_pct: float, area_pct: float) -> str:
    rows = []
    for name, cls in classes.items():
        ids = [i for i, inst in instances.items() if inst.class_name == name]
        total = sum(counts.get(i, 0) for i in ids)
        parts = ", ".join(
            f"{html.escape(instances[i].name)}: {counts.get(i, 0):,}"
            for i in sorted(ids, key=lambda i: instances[i].name)
        )
        swatch = (
            f"<span style='display:inline-block;width:11px;height:11px;"
            f"background:rgb{cls.color};border:1px solid #666;margin-right:4px'></span>"
        )
        rows.append(
            f"<div>{swatch}<b>{html.escape(name)}</b> {total:,} faces"
            f"<div style='margin-left:16px;color:#555'>{parts}</div></div>"
        )
    head = f"<div><b>Coverage</b>: {face_pct:.1f} % of faces, {area_pct:.1f} % of area</div>"
    return "<div style='font-size:12px'>" + head + "".join(rows) + "</div>"


def face_areas(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """Return the area of every face (float64)."""
    v0 = vertices[faces[:, 0]]
    return 0.5 * np.linalg.norm(
        np.cross(vertices[faces[:, 1]] - v0, vertices[faces[:, 2]] - v0), axis=1
    )
