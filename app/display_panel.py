"""The "Display" folder: mode, colour, cost layer with colormap and limits, wireframe, opacity."""

from __future__ import annotations

import contextlib
import threading
from collections.abc import Callable, Iterator
from typing import TYPE_CHECKING

import numpy as np
import viser

from app.colormaps import COLORMAP_NAMES, colorbar_png, layer_stats, robust_limits, swatch_html
from app.histogram import LayerHistogram
from app.notify import guarded
from app.view import DisplayMode, DisplaySettings, available_modes, default_mode
from storage import MapDocument

if TYPE_CHECKING:
    from app.server import MeshmarkApp

#: GLB re-sends (~11 MB at 1M faces) wait this long after the last slider or field change.
DEBOUNCE_S = 0.3


class DisplayPanel:
    """Controls that decide how the map is drawn; one shared state for every browser."""

    def __init__(self, app: MeshmarkApp, gui: viser.GuiApi) -> None:
        self.app = app
        self._quiet = 0
        self._timer: threading.Timer | None = None
        self._timer_lock = threading.Lock()
        self._last_client: viser.ClientHandle | None = None
        self.mode = gui.add_dropdown("Mode", options=[DisplayMode.FIXED.value])
        self.color = gui.add_rgb("Colour", initial_value=(170, 170, 170))
        self.layer = gui.add_dropdown("Layer", options=["(none)"])
        self.cmap = gui.add_dropdown("Colormap", options=COLORMAP_NAMES, initial_value="viridis")
        self.vmin = gui.add_number("Min", initial_value=0.0, step=1e-3)
        self.vmax = gui.add_number("Max", initial_value=1.0, step=1e-3)
        self.robust = gui.add_button("Robust limits (2–98 %)")
        self.colorbar = gui.add_image(colorbar_png(0.0, 1.0, "viridis"), label="Colour bar")
        self.legend = gui.add_html("")
        self.histogram = LayerHistogram(gui)
        self.wireframe = gui.add_checkbox("Wireframe", initial_value=False)
        self.opacity = gui.add_slider("Opacity", min=0.1, max=1.0, step=0.05, initial_value=1.0)

        self.mode.on_update(self._on_change(self._mode_changed))
        self.layer.on_update(self._on_change(self._layer_changed))
        for handle in (self.color, self.cmap, self.vmin, self.vmax, self.wireframe, self.opacity):
            handle.on_update(self._on_change(None))
        self.robust.on_click(self._on_change(self._reset_limits))

    # ------------------------------------------------------------------ state
    @contextlib.contextmanager
    def quiet(self) -> Iterator[None]:
        """Set values from the server without each one triggering a redraw."""
        self._quiet += 1
        try:
            yield
        finally:
            self._quiet -= 1

    def settings(self) -> DisplaySettings:
        """Return the settings the controls show now."""
        layer = self.layer.value if self.layer.value in self.app.doc.layers else None
        return DisplaySettings(
            mode=DisplayMode(self.mode.value),
            color=tuple(int(c) for c in self.color.value),  # type: ignore[arg-type]
            layer=layer,
            cmap=self.cmap.value,
            vmin=float(self.vmin.value),
            vmax=float(self.vmax.value),
            wireframe=bool(self.wireframe.value),
            opacity=float(self.opacity.value),
        )

    def reset_for(self, doc: MapDocument) -> DisplaySettings:
        """Offer the modes and layers of a newly opened map and pick sensible defaults."""
        with self.quiet():
            modes = [m.value for m in available_modes(doc)]
            self.mode.options = modes
            self.mode.value = default_mode(doc).value
            names = sorted(doc.layers) or ["(none)"]
            self.layer.options = names
            self.layer.value = names[0]
            self._apply_limits(doc)
            self._sync_visibility()
        return self.settings()

    def refresh_layers(self, doc: MapDocument) -> None:
        """Offer the current layer names (after layers were added or removed)."""
        with self.quiet():
            names = sorted(doc.layers) or ["(none)"]
            current = self.layer.value
            self.layer.options = names
            self.layer.value = current if current in names else names[0]
            if DisplayMode.COST_LAYER.value not in self.mode.options and doc.layers:
                self.mode.options = [m.value for m in available_modes(doc)]
            self._sync_visibility()

    # ------------------------------------------------------------------ callbacks
    def _on_change(self, first: Callable[[], None] | None) -> Callable[[viser.GuiEvent], None]:
        @guarded("change the display")
        def callback(event: viser.GuiEvent) -> None:
            if self._quiet:
                return
            if first is not None:
                with self.quiet():
                    first()
            self._last_client = event.client
            self._sync_visibility()
            self._schedule()

        return callback

    def _mode_changed(self) -> None:
        if self.mode.value == DisplayMode.COST_LAYER.value:
            self._apply_limits(self.app.doc)

    def _layer_changed(self) -> None:
        self._apply_limits(self.app.doc)

    def _reset_limits(self) -> None:
        self._apply_limits(self.app.doc)

    def _apply_limits(self, doc: MapDocument) -> None:
        name = self.layer.value
        if name not in doc.layers:
            return
        stats = layer_stats(doc.layers[name])
        lo, hi = robust_limits(stats)
        step = float(10 ** np.floor(np.log10(max(hi - lo, 1e-9)) - 3))
        self.vmin.step = self.vmax.step = step
        self.vmin.value = lo
        self.vmax.value = hi
        self.legend.content = swatch_html(stats, self.cmap.value)

    def _sync_visibility(self) -> None:
        mode = self.mode.value
        cost = mode == DisplayMode.COST_LAYER.value
        self.color.visible = mode == DisplayMode.FIXED.value
        for handle in (self.layer, self.cmap, self.vmin, self.vmax, self.robust):
            handle.visible = cost
        self.colorbar.visible = cost
        self.legend.visible = cost
        self.histogram.visible = cost and self.layer.value in self.app.doc.layers
        if cost:
            self.colorbar.image = colorbar_png(
                float(self.vmin.value), float(self.vmax.value), self.cmap.value
            )
            if self.layer.value in self.app.doc.layers:
                values = self.app.doc.layers[self.layer.value]
                stats = layer_stats(values)
                self.legend.content = swatch_html(stats, self.cmap.value)
                vmin, vmax = float(self.vmin.value), float(self.vmax.value)
                self.histogram.show(self.layer.value, values, vmin, vmax)

    def _schedule(self) -> None:
        """Redraw after ``DEBOUNCE_S`` of quiet, so dragging a slider sends one mesh, not fifty."""
        with self._timer_lock:
            if self._timer is not None:
                self._timer.cancel()
            self._timer = threading.Timer(DEBOUNCE_S, self._redraw)
            self._timer.daemon = True
            self._timer.start()

    def _redraw(self) -> None:
        self.app.redraw(self.settings(), client=self._last_client)
