"""`tempera noisy`: Color Me Noisy over a folder of frames, resumable."""
import subprocess

import numpy as np
import pytest

import tempera
from conftest import cli_path  # noqa: F401  (the fixture)


def run(cli, *args):
    return subprocess.run([str(cli), "noisy", *map(str, args)], capture_output=True, text=True, timeout=300)


@pytest.fixture()
def inputs(tmp_path):
    rng = np.random.default_rng(4)
    medium = rng.random((64, 64, 3)).astype(np.float32)
    tempera.write_image(str(tmp_path / "medium.png"), medium)
    (tmp_path / "R").mkdir()
    for f in (1, 2, 3):
        tempera.write_image(str(tmp_path / "R" / f"frame_{f:04d}.png"), medium[4:44, 6:54])
    return tmp_path


def test_frames_are_made_then_current(cli_path, inputs):
    args = ("--exemplar", inputs / "medium.png", "--reference", inputs / "R", "--frames", "1-3", "--out",
            inputs / "out", "--noise", "2.2", "--threads", "2")
    first = run(cli_path, *args)
    assert first.returncode == 0, first.stderr
    assert "3 frame(s) made" in first.stdout
    frames = [tempera.read_image(str(inputs / "out" / f"frame_{f:04d}.png")) for f in (1, 2, 3)]
    assert frames[0].shape == (40, 48, 3)
    assert np.abs(frames[0] - frames[1]).mean() > 0.01  # the frames boil
    again = run(cli_path, *args)
    assert again.returncode == 0 and "0 frame(s) made, 3 current" in again.stdout
    (inputs / "out" / "frame_0002.png").unlink()  # an interrupted run: the rerun makes the same frame
    third = run(cli_path, *args)
    assert "1 frame(s) made, 2 current" in third.stdout
    np.testing.assert_array_equal(tempera.read_image(str(inputs / "out" / "frame_0002.png")), frames[1])


def test_errors_name_the_problem(cli_path, inputs):
    base = ("--exemplar", inputs / "medium.png", "--reference", inputs / "R", "--out", inputs / "out")
    assert run(cli_path, *base).returncode == 2  # no --frames
    bad = run(cli_path, *base, "--frames", "1-3", "--sparkle", "1")
    assert bad.returncode == 2 and "unknown option '--sparkle'" in bad.stderr
    missing = run(cli_path, *base, "--frames", "1-5")
    assert missing.returncode == 1 and "frame_0004.png" in missing.stderr
    same = run(cli_path, "--exemplar", inputs / "medium.png", "--reference", inputs / "R", "--out", inputs / "R",
               "--frames", "1")
    assert same.returncode == 2 and "must not be the --reference folder" in same.stderr
