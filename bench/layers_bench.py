"""Cost layers on the bench terrain: the default stack, and the update after a label edit.

layers_s         every default layer + combinations via LayerStack.compute_all (topology included)
layers_jit_s     first call, minus layers_s: numba compile or cache load
layer_update_ms  update_labels after a 10k-face label change (labels + what depends on them)
"""

from __future__ import annotations

import statistics
import sys
import time

import numpy as np

from bench.terrain import Terrain, make_labels
from bench.timing import median_seconds
from navigation import LayerStack

CHANGED_FACES = 10_000


def _classes() -> dict[str, object]:
    return {"keepout": "lethal", "gravel": {"mode": "cost", "value": 0.4}, "lawn": "free"}


def run(terrain: Terrain, args) -> dict:
    labels = make_labels(terrain)
    instance_classes = {0: "keepout", 1: "gravel", 2: "lawn", 3: "keepout"}
    stack = LayerStack()
    stack.config = stack.config.with_layer(
        stack.config.spec("labels").with_params(classes=_classes())
    )

    def compute():
        return stack.compute_all(
            terrain.vertices, terrain.faces, face_labels=labels, instance_classes=instance_classes
        )

    t0 = time.perf_counter()
    first = compute()
    first_s = time.perf_counter() - t0
    layers_s = median_seconds(compute, repeats=args.repeats, warmup=0)

    # a 10k-face stroke, alternating between two classes so every repeat changes labels
    rng = np.random.default_rng(7)
    start = int(rng.integers(0, terrain.n_faces - CHANGED_FACES))
    stroke = np.arange(start, start + CHANGED_FACES)
    samples = []
    for i in range(args.repeats + 1):
        edited = labels.copy()
        edited[stroke] = 0 if i % 2 == 0 else 1
        t0 = time.perf_counter()
        result = stack.update_labels(edited)
        samples.append(time.perf_counter() - t0)
    update_ms = statistics.median(samples[1:]) * 1000

    final = first.costs["final"]
    print(
        f"[layers] {len(terrain.vertices)} vertices; lethal: "
        + ", ".join(f"{k} {v}" for k, v in first.report.lethal_counts.items())
        + f"; recomputed on update: {', '.join(result.computed)}",
        file=sys.stderr,
    )
    print(
        "[layers] per layer (s): "
        + ", ".join(f"{k} {v:.3f}" for k, v in first.report.seconds.items()),
        file=sys.stderr,
    )
    return {
        "layers_s": layers_s,
        "layers_jit_s": max(0.0, first_s - layers_s),
        "layer_update_ms": update_ms,
        "layers_final_lethal_fraction": float(np.mean(first.lethal["final"])),
        "layers_final_mean_cost": float(np.mean(final[np.isfinite(final)])),
    }
