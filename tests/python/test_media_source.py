"""Exemplar pickers of the fluid and natural-media methods: stills, image
sequences (folder or first file) and movies decoded once by ffmpeg."""
import os
import shutil
import subprocess

import numpy as np
import pytest

import tempera
from tempera.app import media_source
from tempera.app.media_source import MediaError, exemplar_source

FFMPEG = shutil.which("ffmpeg")
needs_ffmpeg = pytest.mark.skipif(FFMPEG is None, reason="ffmpeg is not on PATH (needed to make the test movie)")
SIZE = (24, 32)  # rows, columns
COUNT = 6


def _frames(folder, n=COUNT, prefix="ink_", first=1):
    """n RGBA frames of a square moving right on a half-transparent ground."""
    folder.mkdir(parents=True, exist_ok=True)
    for i in range(n):
        img = np.zeros(SIZE + (4,), np.float32)
        img[..., 3] = 0.5
        img[8:16, 2 + 3 * i:10 + 3 * i] = (1.0, 0.5, 0.0, 1.0)
        tempera.write_image(str(folder / f"{prefix}{first + i:04d}.png"), img, [])
    return folder


def _movie(tmp_path, frames):
    """A lossless RGBA movie (PNG in QuickTime) of the frames."""
    movie = tmp_path / "ink.mov"
    subprocess.run([FFMPEG, "-y", "-v", "error", "-framerate", "10", "-i", str(frames / "ink_%04d.png"),
                    "-c:v", "png", "-pix_fmt", "rgba", str(movie)], check=True)
    return movie


def _read_all(folder):
    return [tempera.read_image(p) for p in media_source.image_files(folder)]


@needs_ffmpeg
def test_movie_decoded_to_its_frames_once_and_again_when_changed(tmp_path):
    frames = _frames(tmp_path / "src")
    movie = _movie(tmp_path, frames)
    folder = exemplar_source("MOVIE", str(movie), str(tmp_path / "cache"))
    decoded, original = _read_all(folder), _read_all(frames)
    assert len(decoded) == COUNT
    for d, o in zip(decoded, original):
        assert d.shape == o.shape
        assert np.abs(d - o).max() < 1.5 / 255  # lossless: the pixels, alpha included
    # Current: reused without ffmpeg (a missing binary would fail).
    assert media_source.decode_movie(str(movie), str(tmp_path / "cache"), ffmpeg="/nonexistent/ffmpeg") == folder
    # A newer movie (two frames fewer) is decoded again.
    shutil.rmtree(frames)
    _movie(tmp_path, _frames(tmp_path / "src", n=COUNT - 2))
    os.utime(movie, ns=(os.stat(movie).st_atime_ns, os.stat(movie).st_mtime_ns + 10**9))
    assert len(media_source.image_files(exemplar_source("MOVIE", str(movie), str(tmp_path / "cache")))) == COUNT - 2
    assert [n for n in os.listdir(tmp_path / "cache") if n.startswith(".")] == []  # no half-decoded folder left


def test_movie_without_ffmpeg_is_a_clear_error(tmp_path, monkeypatch):
    movie = tmp_path / "ink.mp4"
    movie.write_bytes(b"not decoded")
    monkeypatch.setenv("PATH", str(tmp_path / "empty"))
    with pytest.raises(MediaError, match="needs ffmpeg on PATH"):
        exemplar_source("MOVIE", str(movie), str(tmp_path / "cache"))
    assert not os.path.exists(tmp_path / "cache" / "ink")


@needs_ffmpeg
def test_unreadable_movie_names_ffmpeg_and_leaves_no_folder(tmp_path):
    movie = tmp_path / "broken.mp4"
    movie.write_bytes(b"\x00" * 64)
    with pytest.raises(MediaError, match="ffmpeg could not decode"):
        exemplar_source("MOVIE", str(movie), str(tmp_path / "cache"))
    assert os.listdir(tmp_path / "cache") == []


def test_sequence_by_folder_or_first_file(tmp_path):
    seq = _frames(tmp_path / "seq")
    cache = str(tmp_path / "cache")
    assert exemplar_source("SEQUENCE", str(seq), cache) == str(seq)
    # The first file of a sequence alone in its folder: the folder itself.
    assert exemplar_source("SEQUENCE", str(seq / "ink_0001.png"), cache) == str(seq)
    # Beside other images, from a later first file: only its frames, in order.
    _frames(seq, n=2, prefix="other_")
    linked = exemplar_source("SEQUENCE", str(seq / "ink_0003.png"), cache)
    assert linked.startswith(cache)
    got, want = _read_all(linked), [tempera.read_image(str(seq / f"ink_{i:04d}.png")) for i in range(3, COUNT + 1)]
    assert len(got) == len(want) and all(np.array_equal(g, w) for g, w in zip(got, want))


def test_bad_picks_are_named(tmp_path):
    cache = str(tmp_path / "cache")
    _frames(tmp_path / "one", n=1)
    (tmp_path / "empty").mkdir()
    with pytest.raises(MediaError, match="does not exist"):
        exemplar_source("STILL", str(tmp_path / "missing.png"), cache)
    with pytest.raises(MediaError, match="holds no image files"):
        exemplar_source("SEQUENCE", str(tmp_path / "empty"), cache)
    with pytest.raises(MediaError, match="not the first file of a numbered image sequence"):
        exemplar_source("SEQUENCE", str(tmp_path / "one" / "ink_0001.png"), cache)
    with pytest.raises(MediaError, match="not a movie file"):
        exemplar_source("MOVIE", str(tmp_path / "one" / "ink_0001.png"), cache)
    with pytest.raises(MediaError, match="not an image file"):
        exemplar_source("STILL", str(tmp_path / "one"), cache)
    assert exemplar_source("STILL", str(tmp_path / "one" / "ink_0001.png"), cache).endswith("ink_0001.png")
