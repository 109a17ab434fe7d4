from pathlib import Path

import numpy as np

from storage.obj_scan import read_obj_plain, scan_obj


def test_scan_finds_what_loaders_hide(tmp_path: Path):
    (tmp_path / "a.mtl").write_text(
        "newmtl skin\nmap_Kd -s 1 1 1 skin.png\nnewmtl gone\nmap_Kd gone.jpg\n"
    )
    (tmp_path / "skin.png").write_bytes(b"\x89PNG\r\n\x1a\n")
    path = tmp_path / "a.obj"
    path.write_text(
        "mtllib a.mtl\nmtllib missing.mtl\n"
        "v 0 0 0 1 0 0\nv 1 0 0 0 1 0\nv 0 1 0 nan nan nan\n  v 1 1 0 0 0 1\n"
        "vt 0 0\nusemtl skin\nf 1 2 3\nf 1 2\nf 1 2 4 \\\n 3\n"
    )
    scan = scan_obj(path)
    assert (scan.positions, scan.uvs, scan.face_lines) == (4, 1, 3)
    assert (scan.short_faces, scan.polygons, scan.polygon_triangles) == (1, 1, 2)
    assert scan.triangles == 3 and scan.continued_lines == 1
    assert scan.nan_color_ids == [2]
    assert scan.materials == ["skin"]
    assert scan.missing_mtl == ["missing.mtl"]
    assert scan.missing_textures == [("a.mtl", "gone.jpg")]
    assert scan.texture_file == tmp_path / "skin.png"


def test_plain_reader_keeps_file_order_and_negative_ids(tmp_path: Path):
    path = tmp_path / "b.obj"
    path.write_text(
        "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\nv 1 1 0\nf -1 -3 -2\nf 1/1/1 2/2/2 4//4 3\n"
    )
    vertices, colors, faces, short = read_obj_plain(scan_obj(path).text)
    assert vertices.shape == (4, 3) and colors is None and short == 0
    np.testing.assert_array_equal(faces, [[0, 1, 2], [3, 1, 2], [0, 1, 3], [0, 3, 2]])
