"""Shared fixtures: small seeded meshes, and ../shared/data (skipped cleanly when absent)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[1]
SHARED_DATA = Path(os.environ.get("MESHMARK_SHARED_DATA", REPO.parent / "shared" / "data"))


def grid_mesh(n: int = 8, size: float = 1.0, z=None) -> tuple[np.ndarray, np.ndarray]:
    """Return (vertices float64 [(n+1)^2, 3], faces int32 [2 n^2, 3]) of a square grid."""
    xs = np.linspace(0.0, size, n + 1)
    gx, gy = np.meshgrid(xs, xs)
    gz = np.zeros_like(gx) if z is None else z(gx, gy)
    vertices = np.stack([gx.ravel(), gy.ravel(), gz.ravel()], axis=1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    ).astype(np.int32)
    return vertices, faces


@pytest.fixture
def grid():
    return grid_mesh()


@pytest.fixture(scope="session")
def shared_data() -> Path:
    """The real third-party meshes in ../shared/data; skip when they are not there."""
    if not SHARED_DATA.is_dir():
        if os.environ.get("MESHMARK_REQUIRE_SHARED_DATA") == "1":
            pytest.fail(f"MESHMARK_REQUIRE_SHARED_DATA=1 but {SHARED_DATA} is missing")
        pytest.skip(f"shared data not found at {SHARED_DATA}")
    return SHARED_DATA
