"""Maps with everything a map file can hold, and helpers to compare two of them."""

from __future__ import annotations

import io

import numpy as np
import pytest
from PIL import Image

from storage import Goal, Instance, LabelClass, MapData, Texture
from tests.conftest import grid_mesh


def png_bytes(size: int = 8) -> bytes:
    rng = np.random.default_rng(3)
    pixels = rng.integers(0, 255, (size, size, 3), dtype=np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(pixels).save(buffer, format="PNG")
    return buffer.getvalue()


def full_map(n: int = 8, *, offset=(0.0, 0.0, 0.0), seed: int = 0) -> MapData:
    """A grid map with layers (NaN, +inf, -inf), colours, texture, labels and goals."""
    rng = np.random.default_rng(seed)
    v, f = grid_mesh(n, size=10.0, z=lambda x, y: np.sin(x) * np.cos(y))
    v = v + np.asarray(offset)
    nv, nf = len(v), len(f)
    rough = rng.random(nv, dtype=np.float32)
    rough[[0, 5]] = np.nan
    rough[7] = np.inf
    rough[9] = -np.inf
    labels = np.full(nf, -1, dtype=np.int32)
    labels[3:20] = 0
    labels[40:45] = 1
    labels[[60, 2, 90]] = 2
    return MapData(
        vertices=v,
        faces=f,
        layers={"roughness": rough, "height": v[:, 2].astype(np.float32)},
        vertex_colors=rng.integers(0, 256, (nv, 3), dtype=np.uint8),
        texture=Texture(uv=rng.random((nv, 2), dtype=np.float32), image=png_bytes()),
        face_labels=labels,
        classes={
            "stairs": LabelClass("stairs", (200, 10, 10)),
            "grass": LabelClass("grass", (0, 200, 0)),
            "empty": LabelClass("empty", (1, 2, 3)),
        },
        instances={
            0: Instance("stairs", "1"),
            1: Instance("grass", "1"),
            2: Instance("grass", "north"),
            5: Instance("grass", "unused"),
        },
        goals=[
            Goal("dock", (1.0, 2.0, 0.5), (0.0, 0.0, 0.0, 1.0), "map"),
            Goal("far end", (9.5, 9.5, 0.1), (0.0, 0.0, 0.7071067811865476, 0.7071067811865476)),
        ],
    )


@pytest.fixture
def labelled_map() -> MapData:
    return full_map()


def assert_same_map(a: MapData, b: MapData, *, atol: float = 0.0) -> None:
    """Compare everything a file round trip must keep (vertices up to ``atol``)."""
    if atol:
        assert np.abs(a.vertices - b.vertices).max() <= atol
    else:
        np.testing.assert_array_equal(a.vertices, b.vertices)
    np.testing.assert_array_equal(a.faces, b.faces)
    assert list(a.layers) == list(b.layers)
    for name in a.layers:
        # bit-exact: NaN payloads and infinities included
        np.testing.assert_array_equal(
            a.layers[name].view(np.uint32), b.layers[name].view(np.uint32)
        )
    if a.vertex_colors is None:
        assert b.vertex_colors is None
    else:
        np.testing.assert_array_equal(a.vertex_colors, b.vertex_colors)
    if a.texture is None:
        assert b.texture is None
    else:
        assert b.texture is not None
        assert a.texture.image == b.texture.image
        assert a.texture.mime_type == b.texture.mime_type
        np.testing.assert_array_equal(a.texture.uv, b.texture.uv)
    np.testing.assert_array_equal(a.face_labels, b.face_labels)
    assert a.classes == b.classes
    assert list(a.classes) == list(b.classes)
    assert a.instances == b.instances
    assert a.goals == b.goals


def float32_rounded(data: MapData) -> MapData:
    """The same map with vertices rounded to float32, as any file stores them."""
    return MapData(
        vertices=data.vertices.astype(np.float32).astype(np.float64),
        faces=data.faces,
        layers=dict(data.layers),
        vertex_colors=data.vertex_colors,
        texture=data.texture,
        face_labels=data.face_labels,
        classes=dict(data.classes),
        instances=dict(data.instances),
        goals=list(data.goals),
    )
