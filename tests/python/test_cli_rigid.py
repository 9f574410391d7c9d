"""`tempera rigid` (tempera.rigid_cli) on a guide cache's tracks: RGBA frames
written atomically, resumed runs keep finished frames, bad input is named
with a non-zero exit code."""
import json

import numpy as np
import pytest

from tempera import _native, rigid, rigid_tracks
from tempera.__main__ import main

W, H = 240, 160


def _exemplar(folder):
    track = _native.bouncing_ball((30, 40), (4.0, 0), 15, 1.2, 150, 0.6, 0.05, 30)
    rigid_tracks.write_tracks(folder, {"Ball": track}, 1, (0, 1.2))
    (folder / "drawn").mkdir()
    for i, d in enumerate(rigid.generated_exemplar(track, W, H)):
        _native.write_image(str(folder / "drawn" / f"{1 + i:04d}.png"), d, [])


def _cache(folder):
    track = _native.bouncing_ball((200, 30), (-3.0, 0), 14, 1.0, 150, 0.7, -0.05, 24)
    rigid_tracks.write_tracks(folder, {"Target": track}, 1, (0, 1.0))
    (folder / "manifest.json").write_text(json.dumps({"resolution": [W, H]}))


@pytest.fixture()
def inputs(tmp_path):
    (tmp_path / "ex").mkdir()
    (tmp_path / "cache").mkdir()
    _exemplar(tmp_path / "ex")
    _cache(tmp_path / "cache")
    return tmp_path


def _run(inputs, *extra):
    return main(["rigid", "--cache", str(inputs / "cache"), "--exemplar", str(inputs / "ex"),
                 "--out", str(inputs / "out"), *extra])


def test_frames_written_and_resumed(inputs, capsys):
    assert _run(inputs, "--k", "2") == 0
    frames = sorted((inputs / "out").glob("frame_*.png"))
    assert len(frames) == 24
    assert not list((inputs / "out").glob(".*partial*"))
    img = _native.read_image(str(frames[10]), None)
    assert img.shape == (H, W, 4) and img[:, :, 3].max() > 0.9
    assert "24 frames written" in capsys.readouterr().out
    # A resumed run keeps every finished frame; a lost one is made again.
    frames[5].unlink()
    assert _run(inputs, "--k", "2") == 0
    assert "1 frames written, 23 kept" in capsys.readouterr().out
    # Other options: everything again.
    assert _run(inputs, "--k", "1", "--paper") == 0
    assert "24 frames written" in capsys.readouterr().out
    assert _native.read_image(str(frames[0]), None)[:, :, 3].min() == 1.0


def test_bad_input_is_named(inputs, capsys):
    assert _run(inputs, "--k", "0") == 2
    assert "k" in capsys.readouterr().err
    (inputs / "ex" / "drawn" / "0003.png").unlink()
    assert _run(inputs) == 2
    assert "0003.png: drawn frame missing" in capsys.readouterr().err
    assert main(["rigid", "--cache", str(inputs / "nowhere"), "--exemplar", str(inputs / "ex"),
                 "--out", str(inputs / "out")]) == 2
    assert "no rigid-body tracks" in capsys.readouterr().err
    assert _run(inputs, "--object", "Nope") == 2
    assert "no object 'Nope'" in capsys.readouterr().err
