"""The command-level half of the fuzz harness (tests/fuzz/fuzz_rigid.py: the
rigid-body method's tracks, manifest and options, each a run of the native
command) for a few seconds, as ctest's fuzz_smoke runs the in-process half;
`make fuzz` runs both longer."""
import importlib.util
from pathlib import Path

_spec = importlib.util.spec_from_file_location("fuzz_rigid", Path(__file__).parents[1] / "fuzz" / "fuzz_rigid.py")
fuzz_rigid = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(fuzz_rigid)


def test_tracks_and_options_find_nothing(tmp_path, capsys, cli_path):
    assert fuzz_rigid.main(["--seconds", "8", "--work", str(tmp_path), "--tempera", str(cli_path)]) == 0, \
        capsys.readouterr().out
    out = capsys.readouterr().out
    assert "tracks:" in out and "options:" in out and "0 finding(s)" in out


def test_finds_a_command_that_crashes(tmp_path, capsys):
    """A command that dies of a signal on bad tracks is what the harness is for: it reports it."""
    crashing = tmp_path / "tempera"
    crashing.write_text("#!/bin/sh\nkill -SEGV $$\n")
    crashing.chmod(0o755)
    assert fuzz_rigid.main(["--seconds", "2", "--only", "tracks", "--work", str(tmp_path / "work"),
                            "--tempera", str(crashing)]) == 1
    assert "fuzz_rigid: tracks: exit status -11" in capsys.readouterr().out
    assert list((tmp_path / "work").glob("finding_tracks_*/argv.json"))
