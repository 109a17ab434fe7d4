import pytest

from app.paths import PathError, resolve_in


def test_paths_stay_inside_the_data_directory(tmp_path):
    assert resolve_in(tmp_path, "maps/a.h5") == tmp_path.resolve() / "maps" / "a.h5"
    assert resolve_in(tmp_path, str(tmp_path / "b.h5")) == tmp_path.resolve() / "b.h5"
    for bad in ["../x.h5", "/etc/passwd", "maps/../../x.h5", "   "]:
        with pytest.raises(PathError):
            resolve_in(tmp_path, bad)


def test_save_paths_get_the_h5_suffix(tmp_path):
    assert resolve_in(tmp_path, "out", suffix=".h5").name == "out.h5"
    with pytest.raises(PathError, match="h5"):
        resolve_in(tmp_path, "out.ply", suffix=".h5")


def test_symlinks_out_of_the_data_directory_are_refused(tmp_path):
    inside = tmp_path / "data"
    inside.mkdir()
    (inside / "link").symlink_to(tmp_path)
    with pytest.raises(PathError):
        resolve_in(inside, "link/secret.h5")
