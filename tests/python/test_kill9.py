"""Issue 18: `kill -9` at any moment of a `tempera stylize` run leaves only
complete frames, and the rerun produces exactly the frames of a run that was
never interrupted (temporal guide on, so each frame depends on the last, and
warm-started from the last one's matches)."""
import os
import signal
import subprocess
import time

import numpy as np
import pytest

import tempera
from synthetic_cache import make_cache, make_exemplar

FRAMES = list(range(1, 7))


def stylize(cli_path, p, out):
    return [str(cli_path), "stylize", "--guides", str(p / "cache"), "--exemplar", str(p / "paint.png"),
            "--exemplar-guides", str(p / "exemplar"), "--frames", f"{FRAMES[0]}-{FRAMES[-1]}", "--out", str(out),
            "--temporal", "0.5", "--warm-start", "auto", "--threads", "2", "--no-video"]


def frames_of(out):
    return {f: tempera.read_image(str(out / "frames" / f"frame_{f:04d}.png")) for f in FRAMES}


@pytest.fixture(scope="module")
def shot(tmp_path_factory, cli_path):
    p = tmp_path_factory.mktemp("kill9")
    make_cache(p / "cache", frames=FRAMES)
    make_exemplar(p / "exemplar", p / "paint.png")
    start = time.monotonic()
    done = subprocess.run(stylize(cli_path, p, p / "reference"), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    return p, frames_of(p / "reference"), time.monotonic() - start


def kill_when(cli_path, p, out, ready):
    """Starts a run and SIGKILLs it as soon as ready(elapsed) is true."""
    process = subprocess.Popen(stylize(cli_path, p, out), stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    start = time.monotonic()
    while process.poll() is None and not ready(time.monotonic() - start):
        time.sleep(0.002)
    process.send_signal(signal.SIGKILL)
    process.wait()
    return process.returncode


def written(out):
    folder = out / "frames"
    return sorted(f for f in folder.glob("frame_*.png")) if folder.is_dir() else []


@pytest.mark.parametrize("moment", ["at start", "in frame 1", "after 1 frame", "after 3 frames", "late"])
def test_sigkill_leaves_complete_frames_and_the_rerun_matches(cli_path, shot, tmp_path, moment):
    p, reference, seconds = shot
    ready = {
        "at start": lambda t: t > 0.01,
        "in frame 1": lambda t: t > 0.15 * seconds / len(FRAMES),
        "after 1 frame": lambda t: len(written(tmp_path)) >= 1,
        "after 3 frames": lambda t: len(written(tmp_path)) >= 3,
        "late": lambda t: t > 0.8 * seconds,
    }[moment]
    status = kill_when(cli_path, p, tmp_path, ready)
    assert status in (-signal.SIGKILL, 0)
    for path in written(tmp_path):  # every frame there is whole: it reads back as a full image
        assert tempera.read_image(str(path)).shape == reference[1].shape, path
    again = subprocess.run(stylize(cli_path, p, tmp_path), capture_output=True, text=True, timeout=300)
    assert again.returncode == 0, again.stderr
    for f, image in frames_of(tmp_path).items():
        np.testing.assert_array_equal(image, reference[f], err_msg=f"frame {f} after a kill {moment}")
    def visible(folder):
        return sorted(x.name for x in folder.iterdir() if not x.name.startswith("."))

    assert visible(tmp_path / "frames") == sorted([f"frame_{f:04d}.png" for f in FRAMES]
                                                  + ["tempera_stylize.json", "tempera_stylize"])
    # The warm start's matches, one file per frame.
    assert visible(tmp_path / "frames" / "tempera_stylize") == [f"field_{f:04d}.exr" for f in FRAMES]


def test_temporaries_of_killed_writers_are_removed_once_stale(cli_path, shot, tmp_path):
    """A kill -9 while a frame is written leaves its hidden temporary file;
    the next run removes it once it is over an hour old (a live writer's is
    seconds old)."""
    p, reference, _ = shot
    frames = tmp_path / "frames"
    frames.mkdir()
    stale, fresh = frames / ".frame_0003.tmp77-0123456789abcdef.png", frames / ".frame_0004.tmp78-fedcba9876543210.png"
    for path in (stale, fresh):
        path.write_bytes(b"half a png")
    old = time.time() - 2 * 3600
    os.utime(stale, (old, old))
    done = subprocess.run(stylize(cli_path, p, tmp_path), capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    assert not stale.exists() and fresh.exists()
