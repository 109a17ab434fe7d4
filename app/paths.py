"""Keep the browser inside the data directory: it names files, never arbitrary server paths."""

from __future__ import annotations

from pathlib import Path

from storage import MeshmarkError


class PathError(MeshmarkError):
    """A path typed in the browser points outside the data directory or is unusable."""


def resolve_in(data_dir: Path, typed: str, *, suffix: str | None = None) -> Path:
    """Resolve ``typed`` (relative to ``data_dir``, or absolute inside it) and confine it there.

    With ``suffix`` the name gets that suffix when it has none.
    """
    text = typed.strip()
    if not text:
        raise PathError("type a file name first")
    root = data_dir.resolve()
    path = Path(text).expanduser()
    path = (path if path.is_absolute() else root / path).resolve()
    if not path.is_relative_to(root):
        raise PathError(f"{typed!r} is outside the data directory {root}; use a path inside it")
    if suffix and path.suffix.lower() != suffix:
        if path.suffix:
            raise PathError(f"{path.name}: maps are saved as {suffix} files")
        path = path.with_suffix(suffix)
    return path
