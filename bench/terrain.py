"""The seeded synthetic terrain and camera every benchmark group measures on."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

UTM_OFFSET = np.array([500_000.0, 5_700_000.0, 100.0])
SIZE_M = 200.0


@dataclass(eq=False)
class Terrain:
    vertices: np.ndarray  # float64 [N, 3] world
    faces: np.ndarray  # int32 [F, 3]
    cells: int  # grid cells per side

    @property
    def n_faces(self) -> int:
        return len(self.faces)


def make_terrain(n_faces: int, *, seed: int = 0, utm: bool = False) -> Terrain:
    """200 m x 200 m grid, two triangles per cell: sines + noise + two steps + three thin walls."""
    rng = np.random.default_rng(seed)
    n = max(2, round(math.sqrt(n_faces / 2)))
    xs = np.linspace(-SIZE_M / 2, SIZE_M / 2, n + 1)
    gx, gy = np.meshgrid(xs, xs)
    z = (
        1.5 * np.sin(gx / 17.0)
        + 1.0 * np.cos(gy / 11.0)
        + 0.5 * np.sin((gx + gy) / 5.0)
        + rng.normal(0.0, 0.05, gx.shape)
    )
    z += np.where(gx > 30.0, 4.0, 0.0)  # step 1: 4 m
    z += np.where(gy < -40.0, 4.5, 0.0)  # step 2: 4.5 m
    cell = SIZE_M / n
    for x0, h in ((-50.0, 6.0), (10.0, 8.0), (60.0, 10.0)):  # thin walls along y
        z += np.where(np.abs(gx - x0) < 0.6 * cell, h, 0.0) * (np.abs(gy) < 70.0)
    vertices = np.stack([gx.ravel(), gy.ravel(), z.ravel()], axis=1)
    idx = np.arange((n + 1) ** 2).reshape(n + 1, n + 1)
    a, b, c, d = idx[:-1, :-1], idx[:-1, 1:], idx[1:, :-1], idx[1:, 1:]
    faces = np.concatenate(
        [np.stack([a, b, d], -1).reshape(-1, 3), np.stack([a, d, c], -1).reshape(-1, 3)]
    ).astype(np.int32)
    if utm:
        vertices = vertices + UTM_OFFSET
    return Terrain(vertices, faces, n)


def make_layers(terrain: Terrain, *, seed: int = 1, count: int = 6) -> dict[str, np.ndarray]:
    """Six float32 per-vertex layers; the first holds NaN and +inf like real maps do."""
    rng = np.random.default_rng(seed)
    n = len(terrain.vertices)
    layers = {}
    for i in range(count):
        values = rng.random(n, dtype=np.float32)
        if i == 0:
            values[rng.choice(n, n // 100, replace=False)] = np.nan
            values[rng.choice(n, n // 100, replace=False)] = np.inf
        layers[f"layer{i}"] = values
    return layers


def make_labels(terrain: Terrain, *, fraction: float = 0.10, instances: int = 4) -> np.ndarray:
    """int32 [F] instance ids: compact blocks covering ``fraction`` of the faces, -1 elsewhere."""
    f = terrain.n_faces
    labels = np.full(f, -1, dtype=np.int32)
    per = int(f * fraction) // instances
    for i in range(instances):
        start = (i * f) // instances
        labels[start : start + per] = i
    return labels


@dataclass(frozen=True)
class BenchCamera:
    """Pinhole camera (OpenCV axes: +z forward, +y down) that just fits the whole terrain."""

    position: np.ndarray  # world, float64 [3]
    wxyz: np.ndarray  # R_world_camera
    fov: float  # vertical, radians
    width: int
    height: int

    @property
    def aspect(self) -> float:
        return self.width / self.height


def overview_camera(terrain: Terrain, *, width: int = 1280, height: int = 720) -> BenchCamera:
    """Look down at the terrain from the south at 60 degrees pitch, vertical fov 60 degrees."""
    fov = math.radians(60.0)
    lo, hi = terrain.vertices.min(0), terrain.vertices.max(0)
    centre = (lo + hi) / 2
    radius = float(np.linalg.norm(hi - lo)) / 2
    dist = radius / math.sin(fov / 2) * 0.9
    pitch = math.radians(60.0)
    forward = np.array([0.0, math.cos(pitch), -math.sin(pitch)])
    position = centre - forward * dist
    right = np.cross(forward, [0.0, 0.0, 1.0])
    right /= np.linalg.norm(right)
    down = np.cross(forward, right)
    rot = np.stack([right, down, forward], axis=1)  # columns = camera axes in world
    return BenchCamera(position, _matrix_to_wxyz(rot), fov, width, height)


def _matrix_to_wxyz(m: np.ndarray) -> np.ndarray:
    w = math.sqrt(max(0.0, 1 + m[0, 0] + m[1, 1] + m[2, 2])) / 2
    x = math.copysign(math.sqrt(max(0.0, 1 + m[0, 0] - m[1, 1] - m[2, 2])) / 2, m[2, 1] - m[1, 2])
    y = math.copysign(math.sqrt(max(0.0, 1 - m[0, 0] + m[1, 1] - m[2, 2])) / 2, m[0, 2] - m[2, 0])
    z = math.copysign(math.sqrt(max(0.0, 1 - m[0, 0] - m[1, 1] + m[2, 2])) / 2, m[1, 0] - m[0, 1])
    return np.array([w, x, y, z])
