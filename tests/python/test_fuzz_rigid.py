"""The Python half of the fuzz harness (tests/fuzz/fuzz_rigid.py: the rigid-body
method's tracks reader and options) for a few seconds, as ctest's fuzz_smoke
runs the native half; `make fuzz` runs both longer."""
import importlib.util
from pathlib import Path

from tempera.methods.rigid import rigid_tracks

_spec = importlib.util.spec_from_file_location("fuzz_rigid", Path(__file__).parents[1] / "fuzz" / "fuzz_rigid.py")
fuzz_rigid = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fuzz_rigid)


def test_tracks_and_options_find_nothing(tmp_path, capsys):
    assert fuzz_rigid.main(["--seconds", "6", "--work", str(tmp_path)]) == 0, capsys.readouterr().out
    out = capsys.readouterr().out
    assert "tracks:" in out and "options:" in out and "0 finding(s)" in out


def test_finds_unchecked_tracks(tmp_path, capsys, monkeypatch):
    """With the tracks' checks off, wrong types reach the method and the harness reports them."""
    monkeypatch.setattr(rigid_tracks, "_check_tracks", lambda data, path: None)
    assert fuzz_rigid.main(["--seconds", "6", "--only", "tracks", "--work", str(tmp_path)]) == 1
    assert "fuzz_rigid: tracks: " in capsys.readouterr().out
    assert list(tmp_path.glob("finding_tracks_*/argv.json"))
