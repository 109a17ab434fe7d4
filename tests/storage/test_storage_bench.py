"""The storage benchmark still runs and reports every key (no timing assertions here)."""

from types import SimpleNamespace

from bench.storage_bench import run
from bench.terrain import make_terrain


def test_storage_bench_reports_its_keys():
    result = run(make_terrain(2000), SimpleNamespace(repeats=1))
    for key in ("save_ms", "load_ms", "h5py_raw_write_ms", "h5py_raw_read_ms"):
        assert result[key] > 0
    assert result["compression"].startswith("gzip")
    assert result["labelled_faces"] > 0
