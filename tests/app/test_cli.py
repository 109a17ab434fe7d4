"""The ``meshmark`` command as a user runs it: a real subprocess, real files."""

from __future__ import annotations

import re
import subprocess
import sys
import time
import urllib.request
from pathlib import Path

import h5py
import pytest

from static import demo_map_path

MESHMARK = [sys.executable, "-m", "app.cli"]


def run(*args: str, cwd: Path | None = None) -> subprocess.CompletedProcess[str]:
    return subprocess.run(
        [*MESHMARK, *args], capture_output=True, text=True, timeout=120, cwd=cwd, check=False
    )


def test_info_describes_the_demo_map():
    result = run("info", str(demo_map_path()))
    assert result.returncode == 0, result.stderr
    out = result.stdout
    assert "8,100" in out or "8100" in out  # vertices of floor_is_lava
    assert "15,960" in out or "15960" in out  # faces
    for layer in ("roughness", "height_diff", "border"):
        assert layer in out
    assert re.search(r"current", out, re.IGNORECASE)


@pytest.mark.parametrize(
    ("name", "content"),
    [
        ("notes.ply", b"this is not a mesh\n"),
        ("half.h5", b"\x89HDF\r\n\x1a\n" + b"\0" * 64),
        ("empty.obj", b""),
    ],
)
def test_info_on_a_bad_file_fails_clearly(tmp_path, name, content):
    path = tmp_path / name
    path.write_bytes(content)
    result = run("info", str(path))
    assert result.returncode == 2
    assert name in result.stderr
    assert "Traceback" not in result.stderr


def test_convert_writes_the_current_layout(tmp_path):
    out = tmp_path / "demo.h5"
    result = run("convert", str(demo_map_path()), str(out))
    assert result.returncode == 0, result.stderr
    with h5py.File(out, "r") as f:
        assert f["mesh/geometry/vertices"].shape == (8100, 3)
        assert f["mesh"].attrs["IO"] == "MeshIO"


def test_serve_prints_the_url_and_serves_the_page(tmp_path):
    proc = subprocess.Popen(
        [*MESHMARK, "serve", "--port", "0", "--data-dir", str(tmp_path)],
        stdout=subprocess.PIPE,
        stderr=subprocess.STDOUT,
        text=True,
    )
    try:
        url = None
        deadline = time.monotonic() + 90
        lines = []
        while time.monotonic() < deadline and url is None:
            line = proc.stdout.readline()
            if not line:
                break
            lines.append(line)
            match = re.search(r"http://127\.0\.0\.1:(\d+)/", line)
            if match:
                url = match.group(0)
        assert url, f"no URL printed: {''.join(lines)}"
        assert "demo_floor_is_lava" in "".join(lines)
        with urllib.request.urlopen(url, timeout=30) as response:
            assert response.status == 200
            assert b"<html" in response.read(4096).lower()
    finally:
        proc.terminate()
        proc.wait(timeout=30)
