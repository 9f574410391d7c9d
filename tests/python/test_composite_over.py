"""tools/composite_over.py, the fluid demos' last step: straight-alpha RGBA
frames over a background folder or picture; a missing frame is named, exit 2."""
import sys
from pathlib import Path

import numpy as np

from tempera import read_image, write_image

sys.path.insert(0, str(Path(__file__).resolve().parents[2] / "tools"))
import composite_over  # noqa: E402


def _frames(tmp_path):
    over, under = tmp_path / "over", tmp_path / "under"
    over.mkdir()
    under.mkdir()
    for f in (3, 4):
        rgba = np.zeros((8, 10, 4), np.float32)
        rgba[:, :5] = (1.0, 0.0, 0.0, 0.6)  # left half: red at 60 %
        write_image(str(over / f"frame_{f:04d}.png"), rgba)
        write_image(str(under / f"frame_{f:04d}.png"), np.full((8, 10, 3), 0.2 * f, np.float32))
    return over, under


def test_composites_over_each_background_frame(tmp_path):
    over, under = _frames(tmp_path)
    assert composite_over.main(["--over", str(over), "--under", str(under), "--frames", "3-4",
                                "--out", str(tmp_path / "out")]) == 0
    for f in (3, 4):
        got = read_image(str(tmp_path / "out" / f"frame_{f:04d}.png"))
        assert got.shape == (8, 10, 3)
        expected_left = np.array([0.6 + 0.4 * 0.2 * f, 0.4 * 0.2 * f, 0.4 * 0.2 * f])
        assert np.abs(got[:, :5] - expected_left).max() < 1.5 / 255
        assert np.abs(got[:, 5:] - 0.2 * f).max() < 1.5 / 255
    assert (tmp_path / "out" / "contact_sheet.png").is_file()


def test_one_picture_under_every_frame_and_missing_frames_named(tmp_path, capsys):
    over, under = _frames(tmp_path)
    paper = tmp_path / "paper.png"
    write_image(str(paper), np.ones((8, 10, 3), np.float32))
    assert composite_over.main(["--over", str(over), "--under", str(paper), "--frames", "3-4",
                                "--out", str(tmp_path / "out")]) == 0
    got = read_image(str(tmp_path / "out" / "frame_0004.png"))
    assert np.abs(got[:, 5:] - 1).max() < 1e-6 and np.abs(got[0, 0] - [1.0, 0.4, 0.4]).max() < 1.5 / 255
    assert composite_over.main(["--over", str(over), "--under", str(paper), "--frames", "3-5",
                                "--out", str(tmp_path / "out2")]) == 2
    assert "frame_0005.png: missing" in capsys.readouterr().err
