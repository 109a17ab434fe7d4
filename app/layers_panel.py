"""The "Cost layers" folder: layer parameters, class costs, compute, live label layers, export.

"Compute layers" runs the whole layer graph on the job thread, with progress in the clicking
person's notification, and writes every layer as one undo step. After that, label edits and
class-cost changes recompute only the label branch (``LayerStack.update_labels``), debounced,
and write it as derived data (no undo step of its own). Settings live in the map's meta
(``settings``) so they are saved with it and restored when it is opened.
"""

from __future__ import annotations

import contextlib
import dataclasses
import html
import logging
import math
import threading
import time
from collections.abc import Callable, Iterator
from concurrent.futures import Future
from enum import StrEnum
from typing import TYPE_CHECKING, Any

import numpy as np
import viser

from app.cost_layers import (
    DEFAULT_LABEL_LAYER,
    LayerSettings,
    LayerSettingsError,
    compute_layers,
    label_inputs,
    nan_report,
)
from app.notify import guarded, notify_info, report_exception
from navigation import (
    ClassCost,
    HeightDiffMode,
    LabelCostMode,
    LayerConfigError,
    LayerSpec,
    LayerStack,
    NavigationError,
    StackResult,
    export_mesh_navigation_config,
)
from storage import ClassAtom, DocumentChanged, InstanceAtom, LabelAtom, LayerAtom, MapDocument

if TYPE_CHECKING:
    from app.server import MeshmarkApp

logger = logging.getLogger(__name__)

#: Label edits and class-cost changes wait this long for quiet before the label layers follow.
DEBOUNCE_S = 0.3

#: How enum choices read in the dropdowns (other enums show their values).
_CHOICE_LABELS: dict[StrEnum, str] = {
    HeightDiffMode.NORMAL: "current (along the normal)",
    HeightDiffMode.VERTICAL: "2024 (vertical)",
}
_FIELD_LABELS = {"mode": "variant", "method": "distance"}
_HINTS = {
    "threshold": "lethal where the cost is above this",
    "radius": "neighbourhood radius in metres (a flood over mesh edges)",
    "mode": "current mesh_navigation: height along the vertex normal in the tangent plane; "
    "2024: z-range over the xy-disc (the tutorial maps were made with it)",
    "combination_weight": "weight of this layer in a sum layer it feeds (0..1)",
    "border_cost": "cost of vertices on the map border",
    "inscribed_radius": "metres: within it the cost is the inscribed value",
    "inflation_radius": "metres: the cost decays to 0 here",
    "lethal_value": "cost of the lethal vertices",
    "inscribed_value": "cost within the inscribed radius",
    "cost_scaling_factor": "exponential decay between the radii",
    "method": "how distances from lethal vertices spread",
}
_COST_MODES = [m.value for m in LabelCostMode]


def _choice_label(value: StrEnum) -> str:
    return _CHOICE_LABELS.get(value, value.value)


_warm_lock = threading.Lock()
_warmed = False


def warm_kernels_in_background() -> None:
    """Load (or compile) the layer kernels once per process, off the GUI and job threads.

    numba caches them on disk, but the first compile takes ~15 s and loading still takes a
    few; a person should not wait for that on their first "Compute layers".
    """
    global _warmed
    with _warm_lock:
        if _warmed:
            return
        _warmed = True
    threading.Thread(target=_warm, name="layer-kernel-warmup", daemon=True).start()


def _warm() -> None:
    t0 = time.perf_counter()
    try:
        n = 6
        xs = np.linspace(0.0, 1.0, n + 1)
        gx, gy = np.meshgrid(xs, xs)
        vertices = np.stack([gx.ravel(), gy.ravel(), 0.1 * gx.ravel() ** 2], axis=1)
        idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
        a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
        faces = np.concatenate(
            [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
        ).astype(np.int32)
        labels = np.full(len(faces), -1, np.int32)
        labels[:4] = 0
        settings = LayerSettings(class_costs={"warm": ClassCost(LabelCostMode.LETHAL)})
        stack = LayerStack(settings.effective_config())
        stack.compute_all(vertices, faces, face_labels=labels, instance_classes={0: "warm"})
        spec = stack.config.spec("height_diff")
        stack.update_layer(spec.with_params(mode=HeightDiffMode.VERTICAL))
        stack.update_labels(labels)
        logger.info("layer kernels ready in %.1f s", time.perf_counter() - t0)
    except Exception:  # warming is an optimisation; the real compute reports its own errors
        logger.exception("warming the layer kernels failed")


class LayersPanel:
    """Edit, compute and export the cost layers of the open map."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self.gui = gui
        self.settings = LayerSettings()
        self._local = threading.local()  # values set by the server do not count as edits
        self._ui_lock = threading.RLock()
        #: per layer, in config order: its folder and its "inputs" note (None without inputs)
        self._param_folders: list[tuple[Any, Any]] = []
        self._param_widgets: dict[tuple[int, str], Any] = {}
        self._class_handles: list[Any] = []
        self._class_widgets: dict[str, tuple[Any, Any]] = {}
        # the stack of the last compute; used only on the job thread
        self._stack: LayerStack | None = None
        self._stack_doc: MapDocument | None = None
        self._stack_names: frozenset[str] = frozenset()
        self._live = False
        # document events (under the document lock) only note what happened and wake the worker
        self._pending_lock = threading.Lock()
        self._pending: set[str] = set()
        self._renames: list[tuple[str, str]] = []
        self._last_removed: tuple[str, tuple[int, int, int]] | None = None
        self._update_queued = False
        self._label_events = 0  # counts label edits, to catch those made during a compute
        self._wake = threading.Event()
        self._closed = False

        self.label_name = gui.add_text(
            "Label layer name",
            initial_value=DEFAULT_LABEL_LAYER,
            hint="saved as /mesh/vertex_attributes/<name>; mesh_navigation reads it by this name",
        )
        self.name_note = gui.add_markdown("")
        self.compute_button = gui.add_button(
            "Compute layers", hint="compute every layer below and add them to the map"
        )
        self.export_button = gui.add_button(
            "Export mesh_navigation config",
            hint="YAML mesh_map block that makes the saved label layer count in planning",
        )
        self.status = gui.add_markdown("")
        self._classes_folder = gui.add_folder("Class costs")
        self._params_folder = gui.add_folder("Layer parameters", expand_by_default=False)

        self.label_name.on_update(guarded("name the label layer")(self._label_name_changed))
        self.compute_button.on_click(
            guarded("compute the cost layers")(lambda e: self.compute(e.client))
        )
        self.export_button.on_click(guarded("export the mesh_navigation config")(self._export))
        threading.Thread(target=self._worker, name="layers-panel", daemon=True).start()
        warm_kernels_in_background()

    # ------------------------------------------------------------------ state
    @contextlib.contextmanager
    def _quiet(self) -> Iterator[None]:
        """Set widget values from the server without their callbacks acting on them."""
        self._local.quiet = True
        try:
            yield
        finally:
            self._local.quiet = False

    def _is_quiet(self) -> bool:
        return bool(getattr(self._local, "quiet", False))

    def show(self, doc: MapDocument) -> None:
        """Show the settings saved with ``doc`` (defaults if none); forget the last compute."""
        settings, problem = LayerSettings.from_meta(doc.meta)
        with self._pending_lock:
            self._pending.clear()
            self._renames.clear()
            self._last_removed = None
        self._stack = None
        self._stack_doc = None
        self._stack_names = frozenset()
        self._live = False
        self.settings = settings
        with self._quiet():
            self.label_name.value = settings.label_layer or ""
        self.name_note.content = ""
        self.status.content = f"*{problem}*" if problem else ""
        self._rebuild_params()
        self._rebuild_classes()

    def _persist(self) -> None:
        self.settings.save_to(self.app.doc)

    # ------------------------------------------------------------------ document events
    def document_changed(self, event: object) -> None:
        """Note what a document change means for the layers (cheap: under the document lock)."""
        if not isinstance(event, DocumentChanged):
            return
        atom = event.atom
        kind = None
        if isinstance(atom, LabelAtom | InstanceAtom):
            kind = "labels"
            self._label_events += 1
        elif isinstance(atom, ClassAtom):
            kind = "classes" if atom.old is None or atom.new is None else None
            self._note_rename(atom)
        elif isinstance(atom, LayerAtom):
            if event.replay and atom.name in self._stack_names:
                self._live = False  # undo/redo replaced computed layers: stop following labels
            return
        if kind is None:
            return
        with self._pending_lock:
            self._pending.add(kind)
        self._wake.set()

    def _note_rename(self, atom: ClassAtom) -> None:
        # MapDocument.rename_class removes the class, then adds one of the same colour.
        with self._pending_lock:
            if atom.new is None and atom.old is not None:
                self._last_removed = (atom.name, atom.old.color)
                return
            removed, self._last_removed = self._last_removed, None
            added = atom.old is None and atom.new is not None
            if added and removed is not None and removed[1] == atom.new.color:
                self._renames.append((removed[0], atom.name))

    def _worker(self) -> None:
        while not self._closed:
            self._wake.wait()
            while True:  # wait for DEBOUNCE_S without events
                self._wake.clear()
                if self._closed or not self._wake.wait(DEBOUNCE_S):
                    break
            with self._pending_lock:
                pending, self._pending = self._pending, set()
                renames, self._renames = self._renames, []
            try:
                self._process(pending, renames)
            except Exception:  # the panel must keep following edits after a bad moment
                logger.exception("cost layers panel update failed")

    def _process(self, pending: set[str], renames: list[tuple[str, str]]) -> None:
        if "classes" in pending:
            if renames:
                costs = dict(self.settings.class_costs)
                for old, new in renames:
                    if old in costs:
                        costs[new] = costs.pop(old)
                self.settings = dataclasses.replace(self.settings, class_costs=costs)
                self._persist()
            self._rebuild_classes()
        if pending:
            self._request_label_update()

    def _request_label_update(self) -> None:
        if not self._live or self._update_queued:
            return
        self._update_queued = True
        self.app.jobs.submit("Updating the label layers", self._update_labels)

    # ------------------------------------------------------------------ computing
    def compute(self, client: viser.ClientHandle | None = None) -> Future[Any]:
        """Compute every layer in the background; progress and the report go to ``client``."""
        doc = self.app.doc
        settings = self.settings
        note = None
        if client is not None:
            note = client.add_notification(
                "Computing cost layers…",
                "waiting for the job thread",
                loading=True,
                with_close_button=False,
            )
        self.compute_button.disabled = True

        def run() -> StackResult | None:
            try:
                return self._compute(doc, settings, client, note)
            except Exception as exc:
                _remove(note)
                report_exception(client, exc, "compute the cost layers")
                return None
            finally:
                self.compute_button.disabled = False

        return self.app.jobs.submit("Computing cost layers", run)

    def _compute(
        self,
        doc: MapDocument,
        settings: LayerSettings,
        client: viser.ClientHandle | None,
        note: Any,
    ) -> StackResult:
        t0 = time.perf_counter()
        label_events = self._label_events

        def progress(fraction: float, message: str) -> None:
            if note is not None:
                with contextlib.suppress(Exception):  # the client may be gone
                    note.body = f"{fraction * 100:.0f} % — {message}"

        stack, result = compute_layers(doc, settings, progress)
        seconds = time.perf_counter() - t0
        if doc is not self.app.doc:  # another map was opened meanwhile
            _remove(note)
            return result
        self._stack, self._stack_doc = stack, doc
        self._stack_names = frozenset(result.layers)
        self._live = True
        if self._label_events != label_events:  # labels edited while computing: follow them
            self._request_label_update()
        self.app.display_panel.refresh_layers(doc)
        self._report(result, seconds, client, note)
        return result

    def _report(
        self, result: StackResult, seconds: float, client: viser.ClientHandle | None, note: Any
    ) -> None:
        nan = nan_report(result)
        default = result.default_layer
        lethal = (
            f"; {result.report.lethal_counts[default]:,} lethal vertices in {default!r}"
            if default in result.layers
            else ""
        )
        head = f"{len(result.layers)} layers in {seconds:.1f} s{lethal}."
        body = head + (" NaN: none." if not nan else " NaN found — " + "; ".join(nan))
        others = [w for w in result.report.warnings if "NaN" not in w]
        if others:
            body += " Notes: " + "; ".join(others)
        logger.info("cost layers computed: %s", body)
        self.status.content = body
        if note is None:
            return
        try:
            note.title = "Cost layers computed" if not nan else "Cost layers computed, with NaN"
            note.body = body
            note.loading = False
            note.with_close_button = True
            note.color = "yellow" if nan else None
            note.auto_close_seconds = None if nan else 8.0
        except Exception:
            logger.debug("could not update the notification", exc_info=True)

    def _update_labels(self) -> None:
        self._update_queued = False  # edits from now on queue another update
        stack, doc = self._stack, self._stack_doc
        if stack is None or doc is not self.app.doc or not self._live:
            return
        t0 = time.perf_counter()
        labels, classes, _ = label_inputs(doc, stack.config)
        try:
            result = stack.update_labels(
                labels, instance_classes=classes, class_costs=self.settings.class_costs
            )
        except NavigationError as exc:
            raise LayerSettingsError(str(exc)) from None
        with doc.lock:
            if not self._live:  # an undo replaced the layers meanwhile
                return
            for name in result.computed:
                doc.set_layer(name, np.array(result.layers[name].cost), record=False)
        ms = (time.perf_counter() - t0) * 1000
        self.status.content = f"Label layers ({', '.join(result.computed)}) updated in {ms:.0f} ms."

    # ------------------------------------------------------------------ export
    def export_text(self) -> str:
        """Return the mesh_navigation ``mesh_map`` YAML for the current settings."""
        name = self.settings.label_layer
        if name is None:
            raise LayerSettingsError("the layer configuration has no label layer to export")
        try:
            return export_mesh_navigation_config(self.settings.effective_config(), name)
        except LayerConfigError as exc:
            raise LayerSettingsError(str(exc)) from None

    def _export(self, event: viser.GuiEvent) -> None:
        text = self.export_text()
        name = self.settings.label_layer
        if event.client is None:
            return
        event.client.send_file_download(
            f"mesh_navigation_{name}.yaml", text.encode("utf-8"), save_immediately=True
        )
        if name not in self.app.doc.layers:
            notify_info(
                event.client,
                f"No layer {name!r} in the map yet",
                "Compute the layers and save the map: mesh_navigation reads the label costs "
                f"from /mesh/vertex_attributes/{name} in the map file.",
                seconds=10,
            )

    # ------------------------------------------------------------------ label layer name
    def _label_name_changed(self, _event: viser.GuiEvent) -> None:
        if self._is_quiet():
            return
        name = self.label_name.value.strip()
        try:
            settings = self.settings.renamed(name)
        except LayerSettingsError as exc:  # shown under the field while typing, not as a toast
            self.name_note.content = f"<span style='color:#c00'>{html.escape(str(exc))}</span>"
            return
        self.name_note.content = ""
        if settings == self.settings:
            return
        self.settings = settings
        self._persist()
        self._relabel_params()
        self.status.content = f"The label layer will be saved as {name!r} on the next compute."

    # ------------------------------------------------------------------ class costs
    def _rebuild_classes(self) -> None:
        with self._ui_lock:
            for handle in self._class_handles:
                handle.remove()
            self._class_handles = []
            self._class_widgets = {}
            names = list(self.app.doc.classes)
            with self._classes_folder:
                if not names:
                    self._class_handles.append(
                        self.gui.add_markdown("*No label classes yet: add them under Labels.*")
                    )
                for name in names:
                    self._add_class_row(name)

    def _add_class_row(self, name: str) -> None:
        cost = self.settings.class_costs.get(name, ClassCost())
        mode = self.gui.add_dropdown(
            name,
            options=_COST_MODES,
            initial_value=cost.mode.value,
            hint="free: no cost; cost: a fixed cost; lethal: never drive here (+inf)",
        )
        value = self.gui.add_number(
            f"{name} cost",
            initial_value=float(cost.value),
            min=0.0,
            step=0.01,
            visible=cost.mode is LabelCostMode.COST,
        )
        changed = guarded("set the class cost")(lambda _e: self._class_cost_changed(name))
        mode.on_update(changed)
        value.on_update(changed)
        self._class_handles += [mode, value]
        self._class_widgets[name] = (mode, value)

    def set_class_cost(self, name: str, setting: ClassCost | str | float) -> None:
        """Set how class ``name`` counts, as the person would in the panel."""
        cost = ClassCost.from_value(setting)
        with self._ui_lock:
            widgets = self._class_widgets.get(name)
        if widgets is None:
            self._apply_class_cost(name, cost)
            return
        mode, value = widgets
        with self._quiet():
            value.value = float(cost.value)
            mode.value = cost.mode.value
        self._class_cost_changed(name)

    def _class_cost_changed(self, name: str) -> None:
        if self._is_quiet():
            return
        with self._ui_lock:
            widgets = self._class_widgets.get(name)
        if widgets is None:
            return
        mode, value = widgets
        cost_mode = LabelCostMode(mode.value)
        value.visible = cost_mode is LabelCostMode.COST
        try:
            cost = ClassCost(cost_mode, float(value.value))
        except LayerConfigError as exc:
            raise LayerSettingsError(f"{name}: {exc}") from None
        self._apply_class_cost(name, cost)

    def _apply_class_cost(self, name: str, cost: ClassCost) -> None:
        if self.settings.class_costs.get(name, ClassCost()) == cost:
            return
        costs = {**self.settings.class_costs, name: cost}
        self.settings = dataclasses.replace(self.settings, class_costs=costs)
        self._persist()
        with self._pending_lock:
            self._pending.add("costs")
        self._wake.set()

    # ------------------------------------------------------------------ layer parameters
    def _rebuild_params(self) -> None:
        with self._ui_lock:
            for folder, _ in self._param_folders:
                folder.remove()
            self._param_folders = []
            self._param_widgets = {}
            with self._params_folder:
                for index, spec in enumerate(self.settings.config.layers):
                    folder = self.gui.add_folder(_folder_label(spec), expand_by_default=False)
                    with folder:
                        inputs = self.gui.add_markdown(_inputs_text(spec)) if spec.inputs else None
                        self._add_param_widgets(index, spec)
                    self._param_folders.append((folder, inputs))

    def _relabel_params(self) -> None:
        """Show new layer names (a renamed label layer) without rebuilding the widgets."""
        with self._ui_lock:
            for (folder, inputs), spec in zip(
                self._param_folders, self.settings.config.layers, strict=False
            ):
                folder.label = _folder_label(spec)
                if inputs is not None:
                    inputs.content = _inputs_text(spec)

    def _add_param_widgets(self, index: int, spec: LayerSpec) -> None:
        # callbacks find their layer by position: renaming the label layer keeps the order
        for field in dataclasses.fields(spec.params):
            if field.name == "classes":
                continue  # set per class under "Class costs"
            value = getattr(spec.params, field.name)
            label = _FIELD_LABELS.get(field.name, field.name.replace("_", " "))
            hint = _HINTS.get(field.name)
            if isinstance(value, StrEnum):
                choices = {_choice_label(m): m.value for m in type(value)}
                handle = self.gui.add_dropdown(
                    label, options=list(choices), initial_value=_choice_label(value), hint=hint
                )
                read: Callable[[Any], Any] = lambda h, c=choices: c[h.value]  # noqa: E731
            elif math.isfinite(value):
                weight = field.name == "combination_weight"
                handle = self.gui.add_number(
                    label,
                    initial_value=float(value),
                    min=0.0 if weight else None,
                    max=1.0 if weight else None,
                    step=0.001,
                    hint=hint,
                )
                read = lambda h: float(h.value)  # noqa: E731
            else:  # +inf (a stored layer's threshold): a number field cannot show it
                handle = self.gui.add_text(label, initial_value=str(value), hint=hint)
                read = lambda h: float(h.value)  # noqa: E731
            self._param_widgets[(index, field.name)] = handle
            handle.on_update(
                guarded("change the layer parameter")(
                    lambda _e, i=index, k=field.name, h=handle, r=read: self._param_changed(
                        i, k, h, r
                    )
                )
            )

    def param_widget(self, layer: str, key: str) -> Any:
        """Return the GUI input of one layer parameter (None if it has none)."""
        index = self.settings.config.names.index(layer)
        with self._ui_lock:
            return self._param_widgets.get((index, key))

    def set_param(self, layer: str, key: str, value: Any) -> None:
        """Change one layer parameter, as the person would in the panel."""
        spec = self.settings.config.spec(layer)
        try:
            config = self.settings.config.with_layer(spec.with_params(**{key: value}))
        except (LayerConfigError, ValueError) as exc:
            raise LayerSettingsError(f"{layer}: {exc}") from None
        self.settings = dataclasses.replace(self.settings, config=config)
        self._persist()
        self.status.content = "Parameters changed: press *Compute layers* to apply them."

    def _param_changed(self, index: int, key: str, handle: Any, read: Callable[[Any], Any]) -> None:
        if self._is_quiet():
            return
        layer = self.settings.config.layers[index].name
        try:
            try:
                value = read(handle)
            except ValueError:
                raise LayerSettingsError(f"{layer}: {key} must be a number") from None
            self.set_param(layer, key, value)
        except LayerSettingsError:
            old = getattr(self.settings.config.layers[index].params, key)
            with self._quiet():  # show the value in force again
                handle.value = _choice_label(old) if isinstance(old, StrEnum) else _shown(old)
            raise

    def close(self) -> None:
        """Stop the worker thread."""
        self._closed = True
        self._wake.set()


def _folder_label(spec: LayerSpec) -> str:
    return f"{spec.name} ({spec.type.value})"


def _inputs_text(spec: LayerSpec) -> str:
    return "inputs: " + ", ".join(f"`{i}`" for i in spec.inputs)


def _shown(value: float) -> float | str:
    return float(value) if math.isfinite(value) else str(value)


def _remove(note: Any) -> None:
    if note is not None:
        with contextlib.suppress(Exception):
            note.remove()
