"""The "Map" folder: what the map holds, open (path or upload), save, save as, download."""

from __future__ import annotations

import tempfile
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
import viser

from app.notify import guarded, notify_error
from app.paths import PathError, resolve_in
from storage import MapDocument

if TYPE_CHECKING:
    from app.server import MeshmarkApp


def describe(doc: MapDocument) -> str:
    """Return the map summary shown in the panel (markdown)."""
    v = doc.vertices
    if len(v):
        lo, hi = v.min(axis=0), v.max(axis=0)
        bounds = " × ".join(f"{h - lo_:.2f}" for lo_, h in zip(lo, hi, strict=True)) + " m"
    else:
        bounds = "empty"
    name = doc.path.name if doc.path else doc.meta.get("source_name", "(unsaved)")
    layers = ", ".join(sorted(doc.layers)) or "none"
    lines = [
        f"**{name}**{' •' if doc.dirty else ''}",
        f"- layout: {doc.meta.get('layout', doc.meta.get('format', '?'))}",
        f"- {doc.n_vertices:,} vertices, {doc.n_faces:,} faces",
        f"- layers: {layers}",
        f"- bounds: {bounds}",
    ]
    if np.any(doc.origin):
        lines.append(f"- local origin: {tuple(float(x) for x in doc.origin)}")
    if doc.texture is not None:
        lines.append("- textured")
    if doc.vertex_colors is not None:
        lines.append("- vertex colours")
    for warning in doc.warnings[:5]:
        lines.append(f"- ⚠ {warning}")
    return "\n".join(lines)


class FilePanel:
    """Open, save and download controls; paths typed here stay inside the data directory."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self.info = gui.add_markdown("")
        self.open_path = gui.add_text("Open path", initial_value="")
        self.open_button = gui.add_button("Open", hint="Open a map from the data directory")
        self.upload = gui.add_upload_button(
            "Upload map", hint=f"≤ {app.max_upload_bytes // 2**20} MiB (.h5 .ply .obj .glb .stl)"
        )
        self.save_button = gui.add_button("Save", hint="Write the map to its HDF5 file")
        self.save_as_path = gui.add_text("Save as", initial_value="")
        self.save_as_button = gui.add_button("Save as…")
        self.download_button = gui.add_button("Download HDF5")

        self.open_button.on_click(guarded("open the map")(self._open))
        self.upload.on_upload(guarded("open the upload")(self._upload))
        self.save_button.on_click(guarded("save the map")(self._save))
        self.save_as_button.on_click(guarded("save the map")(self._save_as))
        self.download_button.on_click(guarded("download the map")(self._download))

    def refresh(self, doc: MapDocument) -> None:
        """Show the summary of ``doc`` and suggest a save-as name."""
        self.info.content = describe(doc)
        if doc.path is not None and doc.path.suffix.lower() == ".h5":
            suggested = doc.path.name
        else:
            stem = Path(doc.path.name if doc.path else doc.meta.get("source_name", "map")).stem
            suggested = f"{stem}.h5"
        if not self.save_as_path.value:
            self.save_as_path.value = suggested

    def _open(self, event: viser.GuiEvent) -> None:
        path = resolve_in(self.app.data_dir, self.open_path.value)
        if not path.is_file():
            raise PathError(f"{path.name}: no such file in the data directory")
        self.app.confirm_discard(event.client, lambda: self.app.open_path(path, event.client))

    def _upload(self, event: viser.GuiEvent) -> None:
        upload = self.upload.value
        name = Path(upload.name).name or "upload"
        size = len(upload.content)
        if size > self.app.max_upload_bytes:
            notify_error(
                event.client,
                "Upload too large",
                f"{name}: {size / 2**20:.1f} MiB is more than the "
                f"{self.app.max_upload_bytes / 2**20:.0f} MiB limit (--max-upload-mb); "
                "put the file in the data directory and open it by path instead.",
            )
            return
        folder = Path(tempfile.mkdtemp(prefix="meshmark-upload-"))
        path = folder / name
        path.write_bytes(upload.content)
        self.app.confirm_discard(
            event.client, lambda: self.app.open_path(path, event.client, uploaded=True)
        )

    def _save(self, event: viser.GuiEvent) -> None:
        doc = self.app.doc
        if doc.path is None or doc.path.suffix.lower() != ".h5" or doc.meta.get("uploaded"):
            self._save_as(event)
            return
        self.app.save(doc.path, event.client)

    def _save_as(self, event: viser.GuiEvent) -> None:
        path = resolve_in(self.app.data_dir, self.save_as_path.value, suffix=".h5")
        self.app.save(path, event.client)

    def _download(self, event: viser.GuiEvent) -> None:
        self.app.download(event.client)
