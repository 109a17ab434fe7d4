"""Storage: save_map / load_map against a raw h5py write / read of the same arrays.

Each figure is the median of ``--repeats`` runs after a warm-up, ours and the baseline
alternated run by run so that load from other processes shifts both alike. The raw baseline
writes exactly the datasets ``save_map`` writes (same paths, dtypes, shapes,
chunks, gzip level and shuffle; fsynced like the atomic save) from arrays prepared in
advance, and reads them all back. So ``save_ms / h5py_raw_write_ms`` is the cost of what
meshmark adds: normals, the float64 -> local float32 cast, label grouping, the temp file and
rename; ``load_ms / h5py_raw_read_ms`` likewise for layout detection, checks and the document.
"""

from __future__ import annotations

import os
import statistics
import tempfile
from pathlib import Path

import h5py
import numpy as np

from bench.terrain import Terrain, make_labels, make_layers
from bench.timing import median_seconds
from storage import Instance, LabelClass, MapData, load_map, save_map
from storage import hdf5_layout as L
from storage.hdf5_write import CHUNK_ROWS, GZIP_LEVEL, plan_file

COMPRESSION = "gzip"


def bench_map(terrain: Terrain) -> MapData:
    """Build the benchmark map: 6 layers (one with NaN/+inf), 10 % of faces in 4 instances."""
    labels = make_labels(terrain)
    classes = {
        "grass": LabelClass("grass", (0, 160, 0)),
        "stairs": LabelClass("stairs", (200, 120, 0)),
        "keepout": LabelClass("keepout", (220, 0, 0)),
    }
    instances = {
        0: Instance("grass", "1"),
        1: Instance("grass", "2"),
        2: Instance("stairs", "1"),
        3: Instance("keepout", "1"),
    }
    return MapData(
        vertices=terrain.vertices,
        faces=terrain.faces,
        layers=make_layers(terrain),
        face_labels=labels,
        classes=classes,
        instances=instances,
    )


def _paired(ours, baseline, repeats: int) -> tuple[float, float]:
    """Median seconds of ``ours`` and ``baseline``, alternated so machine load hits both alike."""
    ours_s, base_s = [], []
    ours(), baseline()  # warm-up
    for _ in range(repeats):
        ours_s.append(median_seconds(ours, repeats=1, warmup=0))
        base_s.append(median_seconds(baseline, repeats=1, warmup=0))
    return statistics.median(ours_s), statistics.median(base_s)


def run(terrain: Terrain, args) -> dict:
    data = bench_map(terrain)
    repeats = getattr(args, "repeats", 5)
    # the raw baseline gets the finished arrays for free: only the HDF5 I/O is timed
    plan = plan_file(data, "raw.h5")

    def raw_write(path: Path) -> None:
        with h5py.File(path, "w") as f:
            for name, a in plan.datasets.items():
                if a.ndim == 0 or a.size == 0:
                    f.create_dataset(name, data=a)
                else:
                    f.create_dataset(
                        name,
                        data=a,
                        chunks=(min(len(a), CHUNK_ROWS), *a.shape[1:]),
                        compression=COMPRESSION,
                        compression_opts=GZIP_LEVEL,
                        shuffle=True,
                    )
        fd = os.open(path, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)

    def raw_read(path: Path) -> dict[str, np.ndarray]:
        with h5py.File(path, "r") as f:
            return {name: f[name][()] for name in plan.datasets}

    with tempfile.TemporaryDirectory(prefix="meshmark-bench-") as tmp:
        saved, raw = Path(tmp) / "saved.h5", Path(tmp) / "raw.h5"
        save_s, raw_write_s = _paired(
            lambda: save_map(data, saved, compression=COMPRESSION),
            lambda: raw_write(raw),
            repeats,
        )
        load_s, raw_read_s = _paired(lambda: load_map(saved), lambda: raw_read(raw), repeats)
        size_mb = saved.stat().st_size / 1e6
        with h5py.File(saved, "r") as f:
            labelled = sum(ds.shape[0] for g in f[L.LABELS].values() for ds in g.values())
    return {
        "save_ms": save_s * 1000,
        "load_ms": load_s * 1000,
        "h5py_raw_write_ms": raw_write_s * 1000,
        "h5py_raw_read_ms": raw_read_s * 1000,
        "save_vs_raw_write": save_s / raw_write_s,
        "load_vs_raw_read": load_s / raw_read_s,
        "compression": f"{COMPRESSION} level {GZIP_LEVEL} + shuffle, {CHUNK_ROWS}-row chunks",
        "map_file_mb": size_mb,
        "labelled_faces": labelled,
    }
